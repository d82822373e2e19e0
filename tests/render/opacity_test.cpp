// Screen-door transparency (`opacity` per type, core/render/screen_door.h) through the pipeline:
// a large see-through sphere in front of an opaque one lets exactly the dithered share of the
// pixels show the one behind, in the CPU raster and in OpenGL alike.
#include <gtest/gtest.h>

#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/pipeline/runtime.h"
#include "core/render/gl/gl_session.h"
#include "core/render/screen_door.h"
#include "tests/support/image_file.h"
#include "tests/support/one_step_render.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {
namespace {

constexpr int kSize = 64;

// Two spheres of radius 3 on the view axis, type 0 (red) in front of type 1 (blue), seen
// orthographically from +z; `opacity` (YAML, may be empty) and the renderer as given.
ImagePixels render(const std::string &renderer, const std::string &opacity,
                   const std::string &name) {
  const SharedScratchDir scratch("/tmp/lantern_opacity_XXXXXX");
  const std::string &dir = scratch.path();
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const std::string file = dir + "/" + name + ".png";
  const std::string yaml =
      "stats: " + dir + "/stats.jsonl\nscenes:\n  - width: " + std::to_string(kSize) +
      "\n    height: " + std::to_string(kSize) + "\n    radius: 3\n    renderer: " + renderer +
      "\n    culling: {occlusion: none}\n"
      "    camera: {projection: orthographic, position: [0, 0, 20], look_at: [0, 0, 0], "
      "up: [0, 1, 0], zoom: 2}\n"
      "    color: {by: type, palette: [[1, 0, 0], [0, 0, 1]]}\n" +
      opacity + "    output: {pattern: '" + file + "'}\n";
  std::vector<double> xyz = {0, 0, 4, 0, 0, 0};
  std::vector<int32_t> type = {0, 1};
  ParticleDescription d;
  d.count = rank == 0 ? 2 : 0;  // all on rank 0: the others composite an empty frame
  d.position = {xyz.data(), DataType::kFloat64, 0};
  d.type = {type.data(), DataType::kInt32, 0};
  render_one_step(yaml, d);
  if (rank != 0) return {};
  ImagePixels image = read_image(file);
  // The renderer asked for is the one that drew (OpenGL would fall back to the CPU without GL).
  const std::string line = read_text(dir + "/stats.jsonl");
  const std::string drawn_by =
      renderer == "opengl" ? "\"renderer\":\"opengl\"" : "\"renderer\":\"cpu\"";
  EXPECT_NE(line.find(drawn_by), std::string::npos) << line;
  return image;
}

bool blue_at(const ImagePixels &im, int x, int y) {
  const size_t p = (size_t(y) * im.width + x) * im.channels;
  return im.pixels[p + 2] > im.pixels[p];
}

// The 16 x 16 pixels around the centre (inside both spheres' silhouettes), 4 x 4 aligned:
// every 4 x 4 block shows the back sphere at exactly 16 - round(16 opacity) pixels, and at the
// pixels the dither matrix says.
void expect_dithered(const ImagePixels &im, double opacity, const std::string &what) {
  ASSERT_EQ(im.width, kSize) << what << ": " << im.error;
  const uint8_t alpha8 = opacity_alpha8(opacity);
  int blocks = 0;
  for (int by = kSize / 2 - 8; by < kSize / 2 + 8; by += 4)
    for (int bx = kSize / 2 - 8; bx < kSize / 2 + 8; bx += 4) {
      int behind = 0;
      for (int y = by; y < by + 4; ++y)
        for (int x = bx; x < bx + 4; ++x) {
          behind += blue_at(im, x, y);
          EXPECT_EQ(blue_at(im, x, y), !screen_door_keeps(x, y, alpha8))
              << what << " pixel " << x << "," << y;
        }
      EXPECT_EQ(behind, 16 - int(16 * opacity + 0.5)) << what << " block " << bx << "," << by;
      ++blocks;
    }
  EXPECT_EQ(blocks, 16);
}

int world_rank_of() {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

TEST(Opacity, HalfOpaqueShowsExactlyHalfOfTheSphereBehindInEveryFourByFourBlock) {
  for (const char *renderer : {"cpu", "opengl"}) {
    if (std::string(renderer) == "opengl" && !gl_backend_built(GlBackend::kEgl) &&
        !gl_backend_built(GlBackend::kOsmesa))
      continue;
    for (const double opacity : {0.5, 0.25, 0.8125, 0.0}) {
      const ImagePixels im = render(renderer, "    opacity: [" + std::to_string(opacity) + ", 1]\n",
                                    std::string(renderer) + "_half");
      if (world_rank_of() == 0)
        expect_dithered(im, opacity, std::string(renderer) + " " + std::to_string(opacity));
    }
  }
}

TEST(Opacity, OpaqueListGivesTheBytesOfNoList) {
  const ImagePixels none = render("cpu", "", "none"),
                    opaque = render("cpu", "    opacity: [1, 1]\n", "opaque");
  if (world_rank_of() != 0) return;
  ASSERT_EQ(none.width, kSize);
  EXPECT_EQ(none.pixels, opaque.pixels);
  for (int y = kSize / 2 - 8; y < kSize / 2 + 8; ++y)
    for (int x = kSize / 2 - 8; x < kSize / 2 + 8; ++x) EXPECT_FALSE(blue_at(none, x, y));
}

}  // namespace
}  // namespace lantern::testing
