// Super-sampling's down-sampling (core/finish/sample_downsampling.h): the documented s x s
// ordered grid, which samples belong to which pixel, linear-light averaging with exact sRGB
// encoding, alpha, and the nearest sample's depth.
#include <gtest/gtest.h>

#include <algorithm>
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

// Straight alpha (background: transparent): samples nothing covered (alpha 0) add no colour, so
// one covered sample of four gives the surface's own colour at alpha 1/4; a fully covered pixel
// gets the plain mean's bytes; an empty one stays (0, 0, 0, 0).
TEST(StraightAlpha, EdgePixelsKeepTheSurfaceColourWithPartialAlpha) {
  Frame samples(6, 2);  // three pixels of 2 x 2 samples
  const uint8_t nothing[4] = {0, 0, 0, 0};
  samples.clear(nothing);
  const uint8_t orange[4] = {230, 128, 26, 255}, blue[4] = {20, 60, 200, 255};
  std::copy(orange, orange + 4, &samples.rgba[4 * samples.index(1, 1)]);  // pixel 0: one sample
  for (int y = 0; y < 2; ++y)  // pixel 1: two orange, two blue samples
    for (int x = 2; x < 4; ++x)
      std::copy(y == 0 ? orange : blue, (y == 0 ? orange : blue) + 4,
                &samples.rgba[4 * samples.index(x, y)]);
  Frame straight, plain;
  downsample_frame(samples, 2, &straight, SampleAlpha::kStraight);
  downsample_frame(samples, 2, &plain);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(straight.rgba[c], orange[c]) << c;
  EXPECT_EQ(straight.rgba[3], 64);  // 255 / 4 = 63.75
  EXPECT_LT(plain.rgba[0], 200);    // the plain mean mixes in the empty samples' black
  for (int c = 0; c < 4; ++c) EXPECT_EQ(straight.rgba[4 + c], plain.rgba[4 + c]) << c;
  for (int c = 0; c < 4; ++c) EXPECT_EQ(straight.rgba[8 + c], 0) << c;
  EXPECT_EQ(straight.depth[2], kBackgroundDepth);
}

// Straight colour composited over any background B (in linear light) is the plain mean of the
// samples drawn on B, within the bytes' rounding, for every coverage count.
TEST(StraightAlpha, CompositedOverABackgroundIsThePlainMeanOnIt) {
  const uint8_t surface[4] = {200, 90, 40, 255}, background[4] = {30, 160, 90, 255};
  const uint8_t nothing[4] = {0, 0, 0, 0};
  for (int covered = 0; covered <= 16; ++covered) {
    Frame on_nothing(4, 4), on_background(4, 4);
    on_nothing.clear(nothing);
    on_background.clear(background);
    for (int k = 0; k < covered; ++k) {
      std::copy(surface, surface + 4, &on_nothing.rgba[4 * size_t(k)]);
      std::copy(surface, surface + 4, &on_background.rgba[4 * size_t(k)]);
    }
    Frame straight, plain;
    downsample_frame(on_nothing, 4, &straight, SampleAlpha::kStraight);
    downsample_frame(on_background, 4, &plain);
    const double a = straight.rgba[3] / 255.0;
    EXPECT_EQ(straight.rgba[3], (covered * 255 + 8) / 16) << covered;
    for (int c = 0; c < 3; ++c) {
      const double linear =
          srgb_to_linear(straight.rgba[c]) * a + srgb_to_linear(background[c]) * (1.0 - a);
      const double composited = 255.0 * encode(linear / kLinearOne);
      EXPECT_NEAR(composited, plain.rgba[c], 1.0) << covered << " samples, channel " << c;
    }
  }
}

}  // namespace
}  // namespace lantern
