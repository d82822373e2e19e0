// sub_filter_rgb_of_rgba: the bytes of drop_alpha then filter_row<3>(kSub), at every width around
// the vector loop's steps and its stop before the row's end, and not one byte past the scanline.
#include "core/output/png/png_filters.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "tests/support/hash_noise.h"

namespace lantern {
namespace {

TEST(PngFilters, SubOfRgbaIsDropAlphaThenSub) {
  constexpr uint8_t kGuard = 0xA5;
  for (int width = 1; width <= 70; ++width) {
    std::vector<uint8_t> rgba(size_t(width) * 4);
    for (size_t i = 0; i < rgba.size(); ++i)
      rgba[i] = uint8_t(testing::hash(uint32_t(width) * 1000003u + uint32_t(i)) >> 24);
    std::vector<uint8_t> rgb(size_t(width) * 3), expected(1 + rgb.size());
    drop_alpha(rgba.data(), width, rgb.data());
    filter_row<3>(PngFilter::kSub, rgb.data(), nullptr, rgb.size(), expected.data());
    // Guard bytes after the scanline: a store past it would change them.
    std::vector<uint8_t> out(expected.size() + 32, kGuard);
    sub_filter_rgb_of_rgba(rgba.data(), width, out.data());
    ASSERT_EQ(std::vector<uint8_t>(out.begin(), out.begin() + long(expected.size())), expected)
        << "width " << width;
    for (size_t i = expected.size(); i < out.size(); ++i)
      ASSERT_EQ(out[i], kGuard) << "width " << width << ": byte " << i << " past the scanline";
  }
}

}  // namespace
}  // namespace lantern
