// MaxDepthPyramid::covered (and covered_on_base, level 0 alone) against the definition - every
// pixel of the rectangle strictly below z - on random depth images lowered piece by piece
// (propagate after each piece), of odd and even sizes, with rectangles of every size from one pixel
// to the whole image, and depths equal to stored ones, just above and just below them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/view/max_depth_pyramid.h"

namespace lantern {
namespace {

bool every_pixel_below(const std::vector<float> &depth, int w, const PixelRect &r, float z) {
  for (int y = r.y0; y <= r.y1; ++y)
    for (int x = r.x0; x <= r.x1; ++x)
      if (!(depth[size_t(y) * size_t(w) + size_t(x)] < z)) return false;
  return true;
}

// A random rectangle inside w x h: mostly small (sphere-sized), sometimes up to the whole image.
PixelRect random_rect(std::mt19937 &rng, int w, int h) {
  std::uniform_int_distribution<int> kind(0, 3);
  const int most = kind(rng) == 0 ? std::max(w, h) : 9;
  std::uniform_int_distribution<int> extent(1, most);
  const int rw = std::min(w, extent(rng)), rh = std::min(h, extent(rng));
  const int x0 = std::uniform_int_distribution<int>(0, w - rw)(rng);
  const int y0 = std::uniform_int_distribution<int>(0, h - rh)(rng);
  return PixelRect{x0, y0, x0 + rw - 1, y0 + rh - 1};
}

// Every tile of every level above 0 holds the largest of its children (those inside the level
// below): what propagate() keeps true, and what covered() trusts when it answers from a level.
void expect_levels_hold_maxima(const MaxDepthPyramid &p, int step) {
  for (int k = 1; k <= p.levels(); ++k)
    for (int ty = 0; ty < p.level_height(k); ++ty)
      for (int tx = 0; tx < p.level_width(k); ++tx) {
        float m = -1.0f;
        for (int cy = 2 * ty; cy <= std::min(2 * ty + 1, p.level_height(k - 1) - 1); ++cy)
          for (int cx = 2 * tx; cx <= std::min(2 * tx + 1, p.level_width(k - 1) - 1); ++cx)
            m = std::max(m, p.tile(k - 1, cx, cy));
        ASSERT_EQ(p.tile(k, tx, ty), m)
            << "step " << step << " level " << k << " tile " << tx << "," << ty << " of "
            << p.level_width(k) << "x" << p.level_height(k);
      }
}

TEST(MaxDepthPyramid, CoveredMatchesAScanOfEveryPixelAsDepthsAreLowered) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int sizes[][2] = {{1, 1}, {1, 7}, {9, 1}, {33, 17}, {64, 64}, {127, 65}, {300, 211}};
  int64_t queries = 0, covered = 0;
  for (const auto &size : sizes) {
    const int w = size[0], h = size[1];
    std::vector<float> depth(size_t(w) * size_t(h), 1.0f);
    MaxDepthPyramid pyramid;
    pyramid.reset(depth.data(), w, h, 1.0f);
    for (int step = 0; step < 400; ++step) {
      // Lower the depths of a rectangle (as drawing a sphere does), then bring the levels up.
      const PixelRect drawn = random_rect(rng, w, h);
      const float level = 0.2f + 0.7f * u(rng);
      for (int y = drawn.y0; y <= drawn.y1; ++y)
        for (int x = drawn.x0; x <= drawn.x1; ++x) {
          float &d = depth[size_t(y) * size_t(w) + size_t(x)];
          d = std::min(d, level + 0.05f * u(rng));
        }
      pyramid.propagate(drawn);
      ASSERT_NO_FATAL_FAILURE(expect_levels_hold_maxima(pyramid, step));
      for (int q = 0; q < 20; ++q) {
        const PixelRect r = random_rect(rng, w, h);
        // A depth at, just above or just below one the rectangle holds, or anywhere.
        const int px = std::uniform_int_distribution<int>(r.x0, r.x1)(rng);
        const int py = std::uniform_int_distribution<int>(r.y0, r.y1)(rng);
        const float held = depth[size_t(py) * size_t(w) + size_t(px)];
        float z = u(rng) * 1.2f;
        switch (q % 4) {
          case 0:
            z = held;
            break;
          case 1:
            z = std::nextafter(held, 2.0f);
            break;
          case 2:
            z = std::nextafter(held, 0.0f);
            break;
          default:
            break;
        }
        const bool expected = every_pixel_below(depth, w, r, z);
        ASSERT_EQ(pyramid.covered(r, z), expected)
            << w << "x" << h << " step " << step << " rect " << r.x0 << "," << r.y0 << ".." << r.x1
            << "," << r.y1 << " z " << z;
        // Read on level 0 alone: 8-wide compares inside the image, the plain rows at its right
        // edge (rectangles of at most 9 pixels are most of those asked).
        ASSERT_EQ(pyramid.covered_on_base(r, z), expected)
            << w << "x" << h << " step " << step << " rect " << r.x0 << "," << r.y0 << ".." << r.x1
            << "," << r.y1 << " z " << z;
        ++queries, covered += expected;
      }
    }
  }
  // Both answers were asked for often enough to mean something.
  EXPECT_GT(covered, queries / 10);
  EXPECT_LT(covered, queries * 9 / 10);
}

// A pyramid over a strip of columns [0, read_end) of a wider image, as the CPU raster's threads
// each keep one (the columns past it written by another thread): covered_on_base reads no column
// from read_end on, so rectangles near the strip's end take the plain rows instead of the 8-wide
// compares; their answers are still the definition's. (That no column past the strip is read is
// what ThreadSanitizer checks: tests/run_sanitized.sh with -DLANTERN_SANITIZE=thread.)
TEST(MaxDepthPyramid, AStripsAnswersNearItsEndAreTheDefinitions) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int w = 200, h = 40;
  for (const int read_end : {64, 67, 128, 199}) {
    std::vector<float> depth(size_t(w) * size_t(h), 1.0f);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < read_end; ++x) depth[size_t(y) * size_t(w) + size_t(x)] = 0.3f * u(rng);
    MaxDepthPyramid pyramid;
    pyramid.reset(depth.data(), w, h, 1.0f, read_end);
    pyramid.propagate(PixelRect{0, 0, read_end - 1, h - 1});
    int64_t covered = 0, queries = 0;
    for (int q = 0; q < 4000; ++q) {
      // Rectangles of 1 to 8 columns ending within 8 of the strip's end.
      const int rw = std::uniform_int_distribution<int>(1, 8)(rng);
      const int x1 = read_end - 1 - std::uniform_int_distribution<int>(0, 7)(rng);
      const int rh = std::uniform_int_distribution<int>(1, 8)(rng);
      const int y0 = std::uniform_int_distribution<int>(0, h - rh)(rng);
      const PixelRect r{std::max(0, x1 - rw + 1), y0, x1, y0 + rh - 1};
      const float z = 0.1f + 0.25f * u(rng);
      const bool expected = every_pixel_below(depth, w, r, z);
      ASSERT_EQ(pyramid.covered_on_base(r, z), expected)
          << "strip end " << read_end << " rect " << r.x0 << "," << r.y0 << ".." << r.x1 << ","
          << r.y1 << " z " << z;
      ASSERT_EQ(pyramid.covered(r, z), expected) << "strip end " << read_end;
      ++queries, covered += expected;
    }
    EXPECT_GT(covered, queries / 20) << read_end;
    EXPECT_LT(covered, queries * 19 / 20) << read_end;
  }
}

TEST(MaxDepthPyramid, AnEmptyRectangleIsCovered) {
  std::vector<float> depth(16, 1.0f);
  MaxDepthPyramid pyramid;
  pyramid.reset(depth.data(), 4, 4, 1.0f);
  EXPECT_TRUE(pyramid.covered(PixelRect{}, 0.0f));
  EXPECT_FALSE(pyramid.covered(PixelRect{0, 0, 3, 3}, 1.0f));
  EXPECT_TRUE(pyramid.covered(PixelRect{0, 0, 3, 3}, std::nextafter(1.0f, 2.0f)));
}

}  // namespace
}  // namespace lantern
