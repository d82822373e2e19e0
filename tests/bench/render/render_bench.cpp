// lantern-bench-render: what the OpenGL sphere pass costs on this machine, per sphere and per
// frame, apart from culling. Prints median milliseconds of several runs for sphere counts and
// sizes at one image size, so a change to the renderer can be judged side by side.
//   lantern-bench-render [--size 1024] [--runs 7] [--cpu-only]
// --cpu-only: time only the CPU raster (OpenGL columns print as 0), for quick raster changes.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "core/camera/camera.h"
#include "core/common/ms_since.h"
#include "core/render/cpu_sphere_raster.h"
#include "core/render/gl/gl_session.h"
#include "core/view/view_geometry.h"

using namespace lantern;

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// n spheres scattered in a cube of side 10 with radius r, seen from outside.
std::vector<SphereInstance> scatter(int n, float r) {
  std::vector<SphereInstance> s(static_cast<size_t>(n));
  uint32_t h = 12345;
  const auto next = [&h] {
    h = h * 1664525u + 1013904223u;
    return float(h >> 8) / float(1 << 24);
  };
  for (auto &x : s) {
    x = {10 * next() - 5, 10 * next() - 5, 10 * next() - 5, r, {200, 100, 50, 255}};
  }
  return s;
}

}  // namespace

int main(int argc, char **argv) {
  int size = 1024, runs = 7;
  bool cpu_only = false;
  for (int i = 1; i < argc; ++i) {
    const bool valued = i + 1 < argc;
    if (!std::strcmp(argv[i], "--cpu-only")) {
      cpu_only = true;
    } else if (valued && !std::strcmp(argv[i], "--size")) {
      size = std::atoi(argv[++i]);
    } else if (valued && !std::strcmp(argv[i], "--runs")) {
      runs = std::atoi(argv[++i]);
    } else {  // a typo must not run the default benchmark as if it were what was asked for
      std::fprintf(stderr,
                   "lantern-bench-render: unknown option or missing value: %s\n"
                   "usage: lantern-bench-render [--size 1024] [--runs 7] [--cpu-only]\n",
                   argv[i]);
      return 2;
    }
  }
  std::shared_ptr<GlSession> session;
  SphereRenderer *renderer = nullptr;
  if (const Status gl = acquire_renderer(GlBackend::kAuto, &session, &renderer); !gl.ok()) {
    std::fprintf(stderr, "lantern-bench-render: %s\n", gl.message.c_str());
    return 1;
  }
  CameraConfig cfg;
  Camera cam;
  make_camera(cfg, {-5, -5, -5}, {5, 5, 5}, 0.5, size, size, &cam);
  const uint8_t bg[4] = {255, 255, 255, 255};
  const RenderView view = cam.render_view(bg);
  const double px_per_unit = cam.projection[1][1] * size / 2.0 / glm::length(cam.eye - cam.target);
  std::printf("%s, %dx%d, median of %d runs\n", session->description().c_str(), size, size, runs);
  std::printf("%10s %10s %12s %10s %12s %14s %12s %10s\n", "spheres", "radius_px", "draw_ms",
              "read_ms", "total_ms", "spheres_per_s", "cpu_ms", "gl/cpu");
  // The CPU raster on the same spheres, everything drawn (no culling), two column strips on two
  // threads as the pipeline runs it.
  const ViewGeometry g = ViewGeometry::from_camera(cam, 20.0);
  Frame cpu_frame;
  const auto cpu_render = [&](const std::vector<SphereInstance> &spheres) {
    CpuSphereRaster::clear_target(g, bg, &cpu_frame);
    CpuSphereRaster strips[2];
    const int split = size / 2;
    const auto run = [&](int k) {
      strips[k].begin_strip(g, &cpu_frame, k == 0 ? 0 : split, k == 0 ? split - 1 : size - 1);
      for (size_t i = 0; i < spheres.size(); ++i) {
        const SphereInstance &s = spheres[i];
        const glm::dvec3 c = g.to_view(cam.origin + glm::dvec3(s.x, s.y, s.z));
        strips[k].draw(c, s.radius, s.rgba, g.sphere_rect_tight(c, s.radius, 0.05));
      }
    };
    std::thread helper(run, 1);
    run(0);
    helper.join();
  };
  for (const int n : {0, 10000, 50000, 200000, 1000000})
    for (const float r : {0.005f, 0.02f, 0.08f, 0.3f}) {
      if (n == 0 && r != 0.005f) continue;
      const auto spheres = scatter(n, r);
      std::vector<double> draw, read, total;
      for (int k = 0; k < (cpu_only ? 0 : runs); ++k) {
        Frame f;
        RenderTimings t;
        const auto t0 = std::chrono::steady_clock::now();
        renderer->render(view, spheres.data(), spheres.size(), &f, &t);
        total.push_back(ms_since(t0));
        draw.push_back(t.draw_ms);
        read.push_back(t.readback_ms);
      }
      std::vector<double> cpu;
      for (int k = 0; k < runs; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        cpu_render(spheres);
        cpu.push_back(ms_since(t0));
      }
      std::printf("%10d %10.1f %12.1f %10.1f %12.1f %14.3g %12.1f %10.1f\n", n, r * px_per_unit,
                  median(draw), median(read), median(total), n / (median(total) / 1000.0),
                  median(cpu), median(total) / std::max(median(cpu), 1e-3));
    }
  return 0;
}
