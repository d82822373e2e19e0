#include "core/composite/sample_downsampling.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace lantern {
namespace {

double srgb_decode(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

uint32_t to_fixed(double linear) {
  return uint32_t(std::lround(linear * double(kLinearOne)));
}

struct SrgbTables {
  std::array<uint32_t, 256> linear{};  // decode: byte -> fixed-point linear
  // threshold[c]: the fixed-point linear value halfway (in the encoded domain) between bytes c and
  // c + 1; a mean at or above it encodes to c + 1 or more.
  std::array<uint32_t, 255> threshold{};
  SrgbTables() {
    for (int c = 0; c < 256; ++c) linear[size_t(c)] = to_fixed(srgb_decode(c / 255.0));
    for (int c = 0; c < 255; ++c) threshold[size_t(c)] = to_fixed(srgb_decode((c + 0.5) / 255.0));
  }
};

const SrgbTables &tables() {
  static const SrgbTables t;  // built once, thread-safe (magic static)
  return t;
}

// One output row: s sample rows of the sample frame starting at sample row `sy`.
void downsample_row(const Frame &samples, int s, int sy, int out_y, Frame *image) {
  const SrgbTables &t = tables();
  const uint32_t count = uint32_t(s) * uint32_t(s);
  for (int x = 0; x < image->width; ++x) {
    uint32_t sum[3] = {0, 0, 0}, alpha = 0;
    float depth = kBackgroundDepth;
    for (int j = 0; j < s; ++j) {
      const size_t row = samples.index(s * x, sy + j);
      const uint8_t *rgba = samples.rgba.data() + 4 * row;
      const float *d = samples.depth.data() + row;
      for (int i = 0; i < s; ++i) {
        for (int c = 0; c < 3; ++c) sum[c] += t.linear[rgba[4 * i + c]];
        alpha += rgba[4 * i + 3];
        depth = std::min(depth, d[i]);
      }
    }
    const size_t out = image->index(x, out_y);
    uint8_t *o = image->rgba.data() + 4 * out;
    for (int c = 0; c < 3; ++c) o[c] = linear_sum_to_srgb(sum[c], count);
    o[3] = uint8_t((alpha + count / 2) / count);
    image->depth[out] = depth;
  }
}

}  // namespace

SampleOffset sample_offset(int samples_per_axis, int i, int j) {
  const double s = double(samples_per_axis);
  return {(i + 0.5) / s, (j + 0.5) / s};
}

uint32_t srgb_to_linear(uint8_t encoded) {
  return tables().linear[encoded];
}

uint8_t linear_sum_to_srgb(uint32_t linear_sum, uint32_t count) {
  // The number of thresholds the mean reaches, compared as sums (no division): mean >= t  <=>
  // sum >= t * count. 64 * 2^24 fits 32 bits.
  const std::array<uint32_t, 255> &th = tables().threshold;
  int lo = 0, hi = 255;  // answer in [lo, hi]
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (linear_sum >= th[size_t(mid)] * count)
      lo = mid + 1;
    else
      hi = mid;
  }
  return uint8_t(lo);
}

void downsample_frame(const Frame &samples, int samples_per_axis, Frame *image) {
  const int s = std::max(samples_per_axis, 1);
  const int width = samples.width / s, height = samples.height / s;
  if (image->width != width || image->height != height ||
      image->rgba.size() != size_t(width) * size_t(height) * 4 ||
      image->depth.size() != size_t(width) * size_t(height))
    *image = Frame(width, height);
  for (int y = 0; y < height; ++y) downsample_row(samples, s, s * y, y, image);
}

}  // namespace lantern
