// lantern-bench-overlays: what the overlays cost on rank 0 per frame - each overlay alone and all
// of them together (two labels, a colour bar with ticks and title, the box, the axis triad) on a
// finished image of the given size, whose depth is half spheres and half background. Prints a
// table of the median, 10th and 90th percentile milliseconds over --reps frames, and the first
// frame apart (glyphs not yet cached). Usage:
//   lantern-bench-overlays [--size=1024] [--reps=200]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "core/camera/camera.h"
#include "core/finish/overlays/overlays.h"

namespace {

using lantern::Frame;
using lantern::OverlaySettings;

// A finished image: a smooth colour field, spheres' depths (0.3..0.7) on a checker of 64-pixel
// cells and the background depth on the others.
Frame scene_frame(int size) {
  Frame f(size, size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      uint8_t *p = f.rgba.data() + 4 * f.index(x, y);
      p[0] = uint8_t(x * 255 / size), p[1] = uint8_t(y * 255 / size), p[2] = 128, p[3] = 255;
      f.depth[f.index(x, y)] =
          ((x / 64 + y / 64) % 2) ? 1.0f : 0.3f + 0.4f * float(x + y) / float(2 * size);
    }
  return f;
}

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[size_t(q * double(v.size() - 1) + 0.5)];
}

}  // namespace

int main(int argc, char **argv) {
  int size = 1024, reps = 200;
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--size=", 7) == 0)
      size = std::atoi(argv[i] + 7);
    else if (std::strncmp(argv[i], "--reps=", 7) == 0)
      reps = std::atoi(argv[i] + 7);
    else {
      std::fprintf(stderr, "usage: lantern-bench-overlays [--size=N] [--reps=N]\n");
      return 2;
    }
  }
  if (size < 64 || reps < 1) return 2;
  lantern::CameraConfig camera_config;  // automatic: azimuth 30, elevation 20
  lantern::Camera camera;
  if (!lantern::make_camera(camera_config, glm::dvec3(0), glm::dvec3(10), 0.5, size, size, &camera)
           .ok())
    return 1;

  OverlaySettings all;
  all.scene_name = "bench";
  lantern::LabelConfig label;
  label.text = "step {step:06d}   t = {time:.2f}";
  all.labels.push_back(label);
  label.text = "{scene}";
  label.position.corner = lantern::OverlayCorner::kTopRight;
  label.size = 18;
  all.labels.push_back(label);
  all.legend.enabled = true;
  all.legend.title = "c_ke";
  all.legend_colors.by = lantern::ColorBy::kScalar;
  all.legend_colors.colormap = "viridis";
  all.box.enabled = true;
  all.axes.enabled = true;

  struct Case {
    const char *name;
    OverlaySettings settings;
  };
  std::vector<Case> cases;
  OverlaySettings only = all;
  only.legend.enabled = only.box.enabled = only.axes.enabled = false;
  cases.push_back({"labels (2)", only});
  only = all;
  only.labels.clear(), only.box.enabled = only.axes.enabled = false;
  cases.push_back({"legend (bar)", only});
  only = all;
  only.labels.clear(), only.legend.enabled = only.axes.enabled = false;
  cases.push_back({"box", only});
  only = all;
  only.labels.clear(), only.legend.enabled = only.box.enabled = false;
  cases.push_back({"axes", only});
  cases.push_back({"all four", all});

  const Frame base = scene_frame(size);
  std::printf("overlays on a %dx%d image, %d frames each (ms per frame, rank 0)\n", size, size,
              reps);
  std::printf("%-14s %10s %10s %10s %12s\n", "overlay", "median", "p10", "p90", "first frame");
  for (const Case &c : cases) {
    std::unique_ptr<lantern::OverlayPainter> painter;
    if (!lantern::OverlayPainter::open(c.settings, &painter).ok()) {
      std::fprintf(stderr, "no font: this bench needs a build with text and DejaVu Sans\n");
      return 1;
    }
    std::vector<double> ms;
    double first = 0;
    for (int r = 0; r <= reps; ++r) {
      Frame image = base;  // copied outside the timed part
      lantern::OverlayFrame frame;
      frame.step = 1000 + r;  // the label's text changes every frame
      frame.time = 0.005 * frame.step;
      frame.range = std::array<double, 2>{0.0, 2.5 + 0.01 * r};  // a running range
      frame.scalar_name = "c_ke";
      frame.box = {{0, 0, 0}, {10, 10, 10}};
      frame.camera = &camera;
      const auto t0 = std::chrono::steady_clock::now();
      painter->draw(c.settings, frame, &image);
      const double t =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      if (r == 0)
        first = t;
      else
        ms.push_back(t);
    }
    std::printf("%-14s %10.3f %10.3f %10.3f %12.3f\n", c.name, percentile(ms, 0.5),
                percentile(ms, 0.1), percentile(ms, 0.9), first);
  }
  return 0;
}
