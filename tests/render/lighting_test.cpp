// The scene's `lighting` (core/config/lighting.h) through the pipeline, in the CPU
// raster and in OpenGL: the default keys give the bytes of no key, a light from the side lights
// exactly the half of the sphere facing it, ambient-only light is a flat disc of ambient x color,
// and the two renderers agree under a custom light.
#include <gtest/gtest.h>

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/pipeline/runtime.h"
#include "core/render/gl/gl_session.h"
#include "tests/support/image_file.h"
#include "tests/support/one_step_render.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {
namespace {

constexpr int kSize = 96;
// The sphere's radius in pixels (radius 3, zoom 1; see `render`) is measured from the image;
// this only bounds it from below.
constexpr int kMinRadiusPixels = 20;

bool have_gl() {
  return gl_backend_built(GlBackend::kEgl) || gl_backend_built(GlBackend::kOsmesa);
}

int world_rank() {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

// One sphere of radius 3 at the origin, color `rgb` (YAML), on black, seen orthographically from
// +z (camera x = image right, y = image up), with `lighting` (YAML lines, may be empty); `xyz`
// replaces the one sphere by others (the camera fits them), `stats_line` receives the stats.
ImagePixels render(const std::string &renderer, const std::string &lighting,
                   const std::string &name, const std::string &rgb = "[1, 0.6, 0.2]",
                   const std::string &projection = "orthographic", const std::string &radius = "3",
                   std::string *stats_line = nullptr, std::vector<double> xyz = {0, 0, 0}) {
  const SharedScratchDir scratch("/tmp/lantern_lighting_XXXXXX");
  const std::string &dir = scratch.path();
  const int rank = world_rank();
  const std::string file = dir + "/" + name + ".png";
  const std::string yaml = "stats: " + dir +
                           "/stats.jsonl\nscenes:\n  - width: " + std::to_string(kSize) +
                           "\n    height: " + std::to_string(kSize) + "\n    radius: " + radius +
                           "\n    lod: {point_path: true}\n    renderer: " + renderer +
                           "\n    background: [0, 0, 0]\n    culling: {occlusion: none}\n"
                           "    camera: {projection: " +
                           projection +
                           ", position: [0, 0, 20], look_at: [0, 0, 0], up: [0, 1, 0], zoom: 1}\n"
                           "    color: {by: solid, solid: " +
                           rgb + "}\n" + lighting + "    output: {pattern: '" + file + "'}\n";
  ParticleDescription d;
  d.count = rank == 0 ? int64_t(xyz.size() / 3) : 0;
  d.position = {xyz.data(), DataType::kFloat64, 0};
  render_one_step(yaml, d);
  if (rank != 0) return {};
  ImagePixels image = read_image(file);
  const std::string line = read_text(dir + "/stats.jsonl");
  EXPECT_NE(line.find("\"renderer\":\"" + renderer + "\""), std::string::npos) << line;
  if (stats_line) *stats_line = line;
  return image;
}

const uint8_t *pixel(const ImagePixels &im, int x, int y) {
  return &im.pixels[(size_t(y) * im.width + x) * im.channels];
}
bool on_sphere(const ImagePixels &im, int x, int y) {
  const uint8_t *p = pixel(im, x, y);
  return p[0] | p[1] | p[2];  // the background is black, every lit pixel has red > 0
}

// The disc's centre and radius in pixels, from its extent on the middle row and column.
struct Disc {
  double cx = 0, cy = 0, r = 0;
};
Disc disc_of(const ImagePixels &im) {
  int x0 = im.width, x1 = -1, y0 = im.height, y1 = -1;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x)
      if (on_sphere(im, x, y))
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  // The whole disc must be in the image, or its extent says nothing.
  EXPECT_TRUE(x0 > 0 && y0 > 0 && x1 < im.width - 1 && y1 < im.height - 1)
      << x0 << " " << x1 << " " << y0 << " " << y1;
  return {0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.25 * (x1 - x0 + y1 - y0 + 2)};
}

std::vector<const char *> renderers() {
  std::vector<const char *> r = {"cpu"};
  if (have_gl()) r.push_back("opengl");
  return r;
}

TEST(Lighting, DefaultKeysGiveTheBytesOfNoKey) {
  for (const char *renderer : renderers())
    for (const char *projection : {"orthographic", "perspective"}) {
      const std::string what = std::string(renderer) + "_" + projection;
      const ImagePixels none = render(renderer, "", what + "_none", "[1, 0.6, 0.2]", projection);
      const ImagePixels given = render(renderer,
                                       "    lighting: {direction: [0, 0, 2], ambient: 0.2, "
                                       "diffuse: 0.8, specular: 0.3, shininess: 40}\n",
                                       what + "_given", "[1, 0.6, 0.2]", projection);
      if (world_rank() != 0) continue;
      ASSERT_EQ(none.width, kSize) << what << ": " << none.error;
      EXPECT_EQ(none.pixels, given.pixels) << what;
    }
}

// A light from the right (+x), no highlight: n.l = (x - cx) / r on an orthographic sphere, so the
// left half is ambient alone, exactly, and the right half brighter, brightest at the right rim.
TEST(Lighting, LightFromTheSideLightsExactlyTheHalfFacingIt) {
  for (const char *renderer : renderers()) {
    const ImagePixels im =
        render(renderer, "    lighting: {direction: [1, 0, 0], ambient: 0.25, specular: 0}\n",
               std::string(renderer) + "_side");
    if (world_rank() != 0) continue;
    ASSERT_EQ(im.width, kSize) << im.error;
    const Disc d = disc_of(im);
    ASSERT_GT(d.r, kMinRadiusPixels) << renderer;
    const uint8_t ambient[3] = {64, 38, 13};  // 0.25 x (255, 153, 51), rounded
    int unlit = 0, lit = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        const double dx = x - d.cx, dy = y - d.cy;
        if (dx * dx + dy * dy > (d.r - 1.5) * (d.r - 1.5)) continue;  // clear of the silhouette
        const uint8_t *p = pixel(im, x, y);
        if (dx < -0.75) {  // n.l < 0: ambient only
          EXPECT_EQ(p[0], ambient[0]) << renderer << " " << x << "," << y;
          EXPECT_EQ(p[1], ambient[1]) << renderer << " " << x << "," << y;
          ++unlit;
        } else if (dx > 0.75) {
          EXPECT_GT(p[0], ambient[0]) << renderer << " " << x << "," << y;
          ++lit;
        }
      }
    EXPECT_GT(unlit, 500) << renderer;
    EXPECT_GT(lit, 500) << renderer;
    // Brightest pixel of the middle row: at the right rim, where n = l.
    const int row = int(std::lround(d.cy));
    int brightest = 0;
    for (int x = 1; x < kSize; ++x)
      if (pixel(im, x, row)[0] > pixel(im, brightest, row)[0]) brightest = x;
    EXPECT_GT(brightest, d.cx + 0.8 * d.r) << renderer;
  }
}

// A light from the right and towards the viewer, l = (1, 0, 1)/sqrt(2), no highlight (a little
// ambient keeps the whole disc off the black background): the brightest point of a Lambert
// sphere is where n = l, r sin 45 deg right of the centre, at its height.
TEST(Lighting, BrightestPointOfALambertSphereLiesTowardsTheLight) {
  for (const char *renderer : renderers()) {
    const ImagePixels im = render(
        renderer, "    lighting: {direction: [1, 0, 1], ambient: 0.02, diffuse: 1, specular: 0}\n",
        std::string(renderer) + "_lambert", "[0.8, 0.8, 0.8]");
    if (world_rank() != 0) continue;
    ASSERT_EQ(im.width, kSize) << im.error;
    const Disc d = disc_of(im);
    ASSERT_GT(d.r, kMinRadiusPixels) << renderer;
    // Centroid of the pixels at the maximum value (8-bit rounding makes a small plateau).
    int best = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) best = std::max(best, int(pixel(im, x, y)[0]));
    double sx = 0, sy = 0, n = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        if (pixel(im, x, y)[0] == best) sx += x, sy += y, ++n;
    EXPECT_EQ(best, 208) << renderer;  // 204 x (0.02 + 1) at n.l = 1
    EXPECT_NEAR(sx / n - d.cx, d.r * std::sqrt(0.5), 1.5) << renderer;
    EXPECT_NEAR(sy / n - d.cy, 0.0, 1.5) << renderer;
  }
}

// Ambient alone (diffuse 0, specular 0): a flat disc of exactly ambient x color, in either
// projection.
TEST(Lighting, AmbientOnlyIsAFlatDiscOfAmbientTimesColor) {
  for (const char *renderer : renderers())
    for (const char *projection : {"orthographic", "perspective"}) {
      const ImagePixels im = render(renderer,
                                    "    lighting: {direction: [0.3, -0.5, 1], ambient: 0.25, "
                                    "diffuse: 0, specular: 0}\n",
                                    std::string(renderer) + "_flat", "[1, 0.6, 0.2]", projection);
      if (world_rank() != 0) continue;
      ASSERT_EQ(im.width, kSize) << im.error;
      int drawn = 0;
      for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
          if (!on_sphere(im, x, y)) continue;
          const uint8_t *p = pixel(im, x, y);
          ASSERT_EQ(p[0], 64) << renderer << " " << projection << " " << x << "," << y;
          ASSERT_EQ(p[1], 38) << renderer << " " << projection << " " << x << "," << y;
          ASSERT_EQ(p[2], 13) << renderer << " " << projection << " " << x << "," << y;
          ++drawn;
        }
      EXPECT_GT(drawn, 1000) << renderer << " " << projection;
    }
}

// A sphere under a pixel across goes to the CPU point splats (lod.point_path): ambient light alone
// gives it exactly ambient x color there too.
TEST(Lighting, PointSplatsTakeTheLightToo) {
  // 20 x 20 spheres one unit apart fill the image (about 4.5 pixels a unit): radius 0.08 is under
  // half a pixel, so every one is splatted, and drawn where a pixel centre falls on it.
  std::vector<double> xyz;
  for (int j = 0; j < 20; ++j)
    for (int i = 0; i < 20; ++i) xyz.insert(xyz.end(), {i - 9.5, j - 9.5, 0.0});
  for (const char *renderer : renderers()) {
    std::string stats;
    const ImagePixels im = render(renderer,
                                  "    lighting: {direction: [0.3, -0.5, 1], ambient: 0.25, "
                                  "diffuse: 0, specular: 0}\n",
                                  std::string(renderer) + "_splat", "[1, 0.6, 0.2]", "orthographic",
                                  "0.08", &stats, xyz);
    if (world_rank() != 0) continue;
    ASSERT_EQ(im.width, kSize) << im.error;
    EXPECT_NE(stats.find("\"splatted\":400"), std::string::npos) << stats;
    int drawn = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        if (!on_sphere(im, x, y)) continue;
        const uint8_t *p = pixel(im, x, y);
        EXPECT_TRUE(p[0] == 64 && p[1] == 38 && p[2] == 13)
            << renderer << " " << x << "," << y << ": " << int(p[0]) << " " << int(p[1]) << " "
            << int(p[2]);
        ++drawn;
      }
    EXPECT_GT(drawn, 40) << renderer;
  }
}

// The CPU raster and OpenGL under the same custom light, with a highlight: the same tolerance as
// the renderers' comparison without it (culling_test: channels within 1 but for a few pixels).
TEST(Lighting, CpuRasterAndOpenGlAgreeUnderACustomLight) {
  if (!have_gl()) GTEST_SKIP() << "no OpenGL backend built";
  for (const char *projection : {"orthographic", "perspective"})
    for (const char *light : {"    lighting: {direction: [-0.4, 0.6, 0.7], ambient: 0.1, "
                              "diffuse: 0.7, specular: 0.6, shininess: 25}\n",
                              // the headlight (l = v per pixel) with other terms
                              "    lighting: {ambient: 0.1, diffuse: 0.7, specular: 0.6, "
                              "shininess: 12}\n"}) {
      const ImagePixels cpu = render("cpu", light, "agree_cpu", "[0.2, 0.5, 0.9]", projection);
      const ImagePixels gl = render("opengl", light, "agree_gl", "[0.2, 0.5, 0.9]", projection);
      const ImagePixels headlight =
          render("opengl", "", "agree_head", "[0.2, 0.5, 0.9]", projection);
      if (world_rank() != 0) continue;
      ASSERT_EQ(cpu.width, kSize) << cpu.error;
      ASSERT_EQ(gl.width, kSize) << gl.error;
      int coverage = 0, off_by_more = 0, max_channel = 0, both = 0;
      for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
          const bool a = on_sphere(cpu, x, y), b = on_sphere(gl, x, y);
          if (a != b) ++coverage;
          if (!(a && b)) continue;
          ++both;
          int worst = 0;
          for (int c = 0; c < 3; ++c)
            worst = std::max(worst, std::abs(int(pixel(cpu, x, y)[c]) - int(pixel(gl, x, y)[c])));
          max_channel = std::max(max_channel, worst);
          off_by_more += worst > 1;
        }
      EXPECT_GT(both, 1000) << projection;
      // ... and the light is not the default one: most pixels differ from the default image.
      int changed = 0;
      for (size_t i = 0; i < gl.pixels.size(); ++i) changed += gl.pixels[i] != headlight.pixels[i];
      EXPECT_GT(changed, both) << projection;
      EXPECT_LE(coverage, 5) << projection;
      EXPECT_LE(off_by_more, 5) << projection << light << ", max channel difference "
                                << max_channel;
      // The highlight is there, where h = normalize(l + v) meets the normal: some pixel is brighter
      // than diffuse alone could make it (0.8 x 0.9 x 255 = 184 in blue).
      int peak = 0;
      for (size_t i = 2; i < cpu.pixels.size(); i += cpu.channels)
        peak = std::max(peak, int(cpu.pixels[i]));
      EXPECT_GT(peak, 200) << projection;
    }
}

}  // namespace
}  // namespace lantern::testing
