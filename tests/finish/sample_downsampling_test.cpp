// Super-sampling's down-sampling (core/finish/sample_downsampling.h): the documented s x s
// ordered grid, which samples belong to which pixel, linear-light averaging with exact sRGB
// encoding, alpha, and the nearest sample's depth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "core/finish/sample_downsampling.h"
#include "core/view/frame.h"

namespace lantern {
namespace {

double encode(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

TEST(SamplePattern, IsTheOrderedGridOfCellCentres) {
  for (const int s : {1, 2, 4, 8}) {
    for (int j = 0; j < s; ++j)
      for (int i = 0; i < s; ++i) {
        const SampleOffset o = sample_offset(s, i, j);
        EXPECT_DOUBLE_EQ(o.x, (i + 0.5) / s);
        EXPECT_DOUBLE_EQ(o.y, (j + 0.5) / s);
      }
  }
  // samples: 4 -> 2 x 2 at the quarter points; 1 -> the pixel centre.
  EXPECT_DOUBLE_EQ(sample_offset(2, 1, 0).x, 0.75);
  EXPECT_DOUBLE_EQ(sample_offset(2, 1, 0).y, 0.25);
  EXPECT_DOUBLE_EQ(sample_offset(1, 0, 0).x, 0.5);
}

// Image pixel (x, y) is made of sample pixels (s x + i, s y + j) and of nothing else: one dark,
// near sample put at each sample position in turn changes exactly its own image pixel.
TEST(SamplePattern, EachImagePixelAveragesItsOwnBlockOfSamples) {
  const int s = 4, width = 5, height = 3;
  Frame samples(width * s, height * s);
  const uint8_t white[4] = {255, 255, 255, 255};
  for (int sy = 0; sy < samples.height; ++sy)
    for (int sx = 0; sx < samples.width; ++sx) {
      samples.clear(white);
      const size_t k = samples.index(sx, sy);
      samples.rgba[4 * k] = samples.rgba[4 * k + 1] = samples.rgba[4 * k + 2] = 0;
      samples.depth[k] = 0.25f;
      Frame image;
      downsample_frame(samples, s, &image);
      ASSERT_EQ(image.width, width);
      ASSERT_EQ(image.height, height);
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
          const bool mine = x == sx / s && y == sy / s;
          const size_t p = image.index(x, y);
          EXPECT_EQ(image.depth[p], mine ? 0.25f : kBackgroundDepth) << sx << "," << sy;
          EXPECT_EQ(image.rgba[4 * p], mine ? 248 : 255) << sx << "," << sy;  // 15/16 light
        }
    }
}

TEST(LinearLight, EqualSamplesGiveTheirByteBack) {
  for (const uint32_t n : {1u, 4u, 16u, 64u})
    for (int c = 0; c < 256; ++c)
      EXPECT_EQ(linear_sum_to_srgb(n * srgb_to_linear(uint8_t(c)), n), c) << n << " x " << c;
}

// Half black, half white is 50% linear light: sRGB 188 (0.7354 * 255 = 187.5), not the 128 of
// averaging the encoded bytes.
TEST(LinearLight, HalfBlackHalfWhiteIsHalfTheLight) {
  Frame samples(2, 2);
  const uint8_t black[4] = {0, 0, 0, 255};
  samples.clear(black);
  for (const int k : {0, 3}) samples.rgba[4 * k] = samples.rgba[4 * k + 1] = 255;
  Frame image;
  downsample_frame(samples, 2, &image);
  EXPECT_EQ(image.rgba[0], 188);
  EXPECT_EQ(image.rgba[1], 188);
  EXPECT_EQ(image.rgba[2], 0);
  EXPECT_EQ(image.rgba[3], 255);
}

// Every mean of 4 and 16 samples encodes to the byte nearest to it in the sRGB domain, as a
// double computation says (means within 1e-3 of a level of a tie, the fixed-point resolution at the
// dark end, are left out).
TEST(LinearLight, MeanEncodesToTheNearestSrgbByte) {
  for (const uint32_t n : {4u, 16u}) {
    int checked = 0;
    for (uint32_t sum = 0; sum <= n * kLinearOne; sum += 977 + (sum % 13)) {
      const double encoded = 255.0 * encode(double(sum) / n / kLinearOne);
      const double fraction = encoded - std::floor(encoded);
      if (std::abs(fraction - 0.5) < 1e-3) continue;  // within the table's fixed point
      ASSERT_EQ(linear_sum_to_srgb(sum, n), int(std::lround(encoded))) << n << " " << sum;
      ++checked;
    }
    EXPECT_GT(checked, 60000);
  }
}

// Alpha is averaged as is; depth is the nearest sample's.
TEST(LinearLight, AlphaIsAveragedAndDepthIsTheNearestSample) {
  Frame samples(4, 4);
  const uint8_t clear[4] = {10, 20, 30, 0};
  samples.clear(clear);
  for (int k = 0; k < 6; ++k) samples.rgba[4 * k + 3] = 255;  // 6 of 16 opaque
  samples.depth[samples.index(3, 2)] = 0.5f;
  samples.depth[samples.index(1, 3)] = 0.75f;
  Frame image;
  downsample_frame(samples, 4, &image);
  EXPECT_EQ(image.rgba[3], 96);  // 6 * 255 / 16 = 95.6
  EXPECT_EQ(image.depth[0], 0.5f);
  EXPECT_EQ(image.rgba[0], 10);
  EXPECT_EQ(image.rgba[1], 20);
}

}  // namespace
}  // namespace lantern
