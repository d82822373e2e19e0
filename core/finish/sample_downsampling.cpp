#include "core/finish/sample_downsampling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>

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
  // threshold[255] is a sentinel no sum reaches (2^25 << 6 > 64 * 2^24), ending the scan below.
  std::array<uint32_t, 256> threshold{};
  // first_code[b]: the thresholds at or below b << kBucketShift, i.e. the encoded byte of the
  // bucket's lowest linear value. Thresholds lie more than a bucket apart, so the byte of any
  // value in the bucket is this or the next one: one or two comparisons instead of a search.
  static constexpr int kBucketShift = 12;
  std::array<uint8_t, (kLinearOne >> kBucketShift) + 1> first_code{};
  SrgbTables() {
    for (int c = 0; c < 256; ++c) linear[size_t(c)] = to_fixed(srgb_decode(c / 255.0));
    for (int c = 0; c < 255; ++c) threshold[size_t(c)] = to_fixed(srgb_decode((c + 0.5) / 255.0));
    threshold[255] = kLinearOne * 2;
    int code = 0;
    for (size_t b = 0; b < first_code.size(); ++b) {
      while (code < 255 && threshold[size_t(code)] <= (uint32_t(b) << kBucketShift)) ++code;
      first_code[b] = uint8_t(code);
    }
  }
  // The number of thresholds t with sum >= t * 2^shift (mean >= t, compared without division:
  // 64 * 2^24 fits 32 bits) for the sum of 2^shift values: the nearest sRGB byte to the mean.
  uint8_t encode(uint32_t linear_sum, int shift) const {
    int code =
        first_code[std::min<size_t>(linear_sum >> (shift + kBucketShift), first_code.size() - 1)];
    while (linear_sum >= threshold[size_t(code)] << shift) ++code;
    return uint8_t(code);
  }
  // The same for the alpha-weighted mean weighted_sum / weight (weight > 0), compared without
  // division; with every weight equal it gives encode()'s byte exactly.
  uint8_t encode_weighted(uint64_t weighted_sum, uint64_t weight) const {
    int code = first_code[std::min<size_t>(size_t((weighted_sum / weight) >> kBucketShift),
                                           first_code.size() - 1)];
    while (weighted_sum >= uint64_t(threshold[size_t(code)]) * weight) ++code;
    return uint8_t(code);
  }
};

const SrgbTables &tables() {
  static const SrgbTables t;  // built once, thread-safe (magic static)
  return t;
}

// One output row: S sample rows of the sample frame starting at sample row `sy` (S a compile-time
// constant so the sample loops unroll). kStraight (SampleAlpha::kStraight): colour is the
// alpha-weighted mean in linear light, so samples nothing covered (alpha 0) add no colour and an
// edge pixel keeps its surface's colour with the share of samples that cover it as alpha; a pixel
// no sample covered is (0, 0, 0, 0). Otherwise the plain mean of every sample.
template <int S, bool kStraight>
void downsample_row(const Frame &samples, int sy, int out_y, Frame *image) {
  // sy: the sample row of the pixel row; out_y: its row in *image.
  constexpr int s = S, shift = S == 8 ? 6 : S == 4 ? 4 : S == 2 ? 2 : 0;  // log2(S * S)
  constexpr uint32_t count = uint32_t(S) * uint32_t(S);
  // Weighted sums reach 64 x 255 x 2^24: beyond 32 bits.
  using Sum = std::conditional_t<kStraight, uint64_t, uint32_t>;
  const SrgbTables &t = tables();
  for (int x = 0; x < image->width; ++x) {
    Sum sum[3] = {0, 0, 0};
    uint32_t alpha = 0;
    float depth = kBackgroundDepth;
    for (int j = 0; j < s; ++j) {
      const size_t row = samples.index(s * x, sy + j);
      const uint8_t *rgba = samples.rgba.data() + 4 * row;
      const float *d = samples.depth.data() + row;
      for (int i = 0; i < s; ++i) {
        const uint32_t a = rgba[4 * i + 3];
        for (int c = 0; c < 3; ++c) {
          if constexpr (kStraight)
            sum[c] += uint64_t(t.linear[rgba[4 * i + c]]) * a;
          else
            sum[c] += t.linear[rgba[4 * i + c]];
        }
        alpha += a;
        depth = std::min(depth, d[i]);
      }
    }
    const size_t out = image->index(x, out_y);
    uint8_t *o = image->rgba.data() + 4 * out;
    for (int c = 0; c < 3; ++c) {
      if constexpr (kStraight)
        o[c] = alpha == 0 ? 0 : t.encode_weighted(sum[c], alpha);
      else
        o[c] = t.encode(sum[c], shift);
    }
    o[3] = uint8_t((alpha + count / 2) >> shift);
    image->depth[out] = depth;
  }
}

template <int S>
void downsample_row_as(SampleAlpha mode, const Frame &samples, int sy, int out_y, Frame *image) {
  if (mode == SampleAlpha::kStraight)
    downsample_row<S, true>(samples, sy, out_y, image);
  else
    downsample_row<S, false>(samples, sy, out_y, image);
}

// Image rows [first, first + out->height) into rows [0, out->height) of *out.
void downsample_rows(const Frame &samples, int s, int first, SampleAlpha mode, Frame *out) {
  for (int y = 0; y < out->height; ++y) {
    const int sy = s * (first + y);
    switch (s) {
      case 2:
        downsample_row_as<2>(mode, samples, sy, y, out);
        break;
      case 4:
        downsample_row_as<4>(mode, samples, sy, y, out);
        break;
      case 8:
        downsample_row_as<8>(mode, samples, sy, y, out);
        break;
      default:
        downsample_row_as<1>(mode, samples, sy, y, out);
    }
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
  int shift = 0;
  while ((uint32_t(1) << shift) < count) ++shift;
  return tables().encode(linear_sum, shift);
}

void downsample_band(const Frame &samples, int samples_per_axis, int first_row, int rows,
                     Frame *band, SampleAlpha mode) {
  const int s = std::max(samples_per_axis, 1);
  const int width = samples.width / s;
  if (band->width != width || band->height != rows ||
      band->rgba.size() != size_t(width) * size_t(rows) * 4 ||
      band->depth.size() != size_t(width) * size_t(rows))
    *band = Frame(width, rows);
  downsample_rows(samples, s, first_row, mode, band);
}

void downsample_frame(const Frame &samples, int samples_per_axis, Frame *image, SampleAlpha mode) {
  const int s = std::max(samples_per_axis, 1);
  downsample_band(samples, s, 0, samples.height / s, image, mode);
}

}  // namespace lantern
