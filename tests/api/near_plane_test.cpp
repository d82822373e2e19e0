// Spheres cut by the near plane through the C API: OpenGL draws the part beyond the plane, as the
// CPU raster does (OpenGL used to clip such spheres away).
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/api/api_fixture.h"
#include "tests/support/image_file.h"

namespace lantern::testing {
namespace {

class NearPlane : public ApiTest {
 protected:
  // Renders particles at `x` (interleaved) with radii `radius` through one scene of 160 x 120
  // with `renderer` and the scene keys `keys`; returns the image, empty if `renderer: opengl` is
  // not available in this build.
  ImagePixels render(const std::string &name, const std::vector<double> &x,
                     const std::vector<double> &radius, const std::string &renderer,
                     const std::string &keys) {
    const std::string scene =
        "    background: [0, 0, 0]\n    radius: per_particle\n"
        "    renderer: " +
        renderer + "\n" + keys;
    const lantern_status st = open(scene_config(name, 160, 120, scene));
    if (renderer == "opengl" && st == LANTERN_ERR_CONFIG) return {};  // built without OpenGL
    EXPECT_EQ(st, LANTERN_OK) << message();
    lantern_particles p = interleaved(x);
    p.radius = {radius.data(), LANTERN_FLOAT64, 0};
    EXPECT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
    EXPECT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
    lantern_close(ctx_);
    ctx_ = nullptr;
    return read_image(png(name, 0));
  }

  // The `renderer` field of the last stats line's first scene.
  std::string renderer_used() const {
    std::ifstream in(dir_ / "stats.jsonl");
    std::string line, last;
    while (std::getline(in, line)) last = line;
    return last.empty() ? "" : nlohmann::json::parse(last)["scenes"][0].value("renderer", "");
  }
};

struct Difference {
  int cpu_drawn = 0, gl_drawn = 0, coverage = 0, off_by_more = 0, max_channel = 0;
};

Difference compare(const ImagePixels &gl, const ImagePixels &cpu) {
  Difference d;
  EXPECT_EQ(gl.error, "");
  EXPECT_EQ(cpu.error, "");
  EXPECT_EQ(gl.pixels.size(), cpu.pixels.size());
  const size_t c = size_t(cpu.channels);
  for (size_t i = 0; i + c <= std::min(gl.pixels.size(), cpu.pixels.size()); i += c) {
    const bool in_cpu = cpu.pixels[i] | cpu.pixels[i + 1] | cpu.pixels[i + 2];
    const bool in_gl = gl.pixels[i] | gl.pixels[i + 1] | gl.pixels[i + 2];
    d.cpu_drawn += in_cpu, d.gl_drawn += in_gl, d.coverage += in_cpu != in_gl;
    int worst = 0;
    if (in_cpu && in_gl)
      for (size_t k = 0; k < c; ++k)
        worst = std::max(worst, std::abs(gl.pixels[i + k] - cpu.pixels[i + k]));
    d.off_by_more += worst > 1;
    d.max_channel = std::max(d.max_channel, worst);
  }
  return d;
}

const char *const kCamera =
    "    camera: {position: [0, -10, 0], look_at: [0, 0, 0], near: 9.4, far: 100, fov: 60}\n";

TEST_F(NearPlane, OffAxisSphereCutByTheNearPlaneIsTheSameCrescentInBothRenderers) {
  // The reproduction of the report: one sphere at (4, 0, 0) of radius 1, the near plane at depth
  // 9.4 through it. The CPU raster draws a crescent of 126 pixels; OpenGL used to draw none.
  const std::vector<double> x = {4, 0, 0}, r = {1};
  const ImagePixels gl = render("gl", x, r, "opengl", kCamera);
  if (gl.pixels.empty()) GTEST_SKIP() << "this Lantern is built without OpenGL";
  const Difference d = compare(gl, render("cpu", x, r, "cpu", kCamera));
  EXPECT_EQ(d.cpu_drawn, 126);
  EXPECT_LE(d.coverage, 1) << d.gl_drawn << " pixels drawn by OpenGL";
  EXPECT_LE(d.max_channel, 1);
}

TEST_F(NearPlane, GridCutByTheNearPlaneMatchesTheCpuRasterUnderAuto) {
  // 35 spheres on a 7 x 5 grid across the view, the near plane through the middle row of them:
  // `renderer: auto` picks OpenGL for spheres this large, and must draw what the CPU raster does.
  std::vector<double> x, r;
  for (int k = 0; k < 5; ++k)
    for (int i = 0; i < 7; ++i) {
      x.insert(x.end(), {2.0 * (i - 3), 0.6 * (k - 2), 1.5 * (k - 2)});
      r.push_back(1.0);
    }
  const std::string camera =
      "    camera: {position: [0, -10, 0], look_at: [0, 0, 0], near: 9.4, far: 100, fov: 40}\n";
  const ImagePixels gl = render("auto", x, r, "auto", camera);
  if (renderer_used() != "opengl") GTEST_SKIP() << "auto chose " << renderer_used();
  const Difference d = compare(gl, render("cpu", x, r, "cpu", camera));
  EXPECT_GT(d.cpu_drawn, 3000);
  EXPECT_LE(d.coverage, 3) << d.gl_drawn << " drawn by OpenGL, " << d.cpu_drawn << " by the CPU";
  // Where two spheres intersect, float and double depths may disagree on the nearer one.
  EXPECT_LE(d.off_by_more, 10) << "max channel difference " << d.max_channel;
}

}  // namespace
}  // namespace lantern::testing
