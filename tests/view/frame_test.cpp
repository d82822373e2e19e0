// Frame::clear: frames below and above the size from which it streams its stores (whole groups of
// four pixels and the pixels after the last group), filled with other bytes first, hold the
// background colour and depth in every pixel afterwards, and drop what a renderer said of them.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <utility>

#include "core/view/frame.h"

namespace lantern {
namespace {

TEST(Frame, ClearWritesTheBackgroundToEveryPixelAtEverySize) {
  const uint8_t background[4] = {10, 20, 30, 255};
  const std::pair<int, int> sizes[] = {{1, 1},     {3, 5},    {511, 512},  {512, 512},
                                       {513, 511}, {1023, 3}, {1024, 1024}};
  for (const auto &[w, h] : sizes) {
    Frame f(w, h);
    for (size_t i = 0; i < f.rgba.size(); ++i) f.rgba[i] = uint8_t(i * 7 + 1);
    for (size_t i = 0; i < f.depth.size(); ++i) f.depth[i] = -float(i);
    f.drawn_within = DrawnWithin{0, 0, 1, 1, {}};
    f.clear(background);
    EXPECT_FALSE(f.drawn_within.has_value());
    size_t wrong = 0;
    for (size_t i = 0; i < f.pixel_count(); ++i)
      wrong += f.depth[i] != kBackgroundDepth || std::memcmp(&f.rgba[4 * i], background, 4) != 0;
    EXPECT_EQ(wrong, 0u) << w << " x " << h;
  }
}

}  // namespace
}  // namespace lantern
