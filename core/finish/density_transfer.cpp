#include "core/finish/density_transfer.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace lantern {
namespace {

constexpr double kLogDecades = 1e4;  // auto range of the log transfer: hi / 10^4 .. hi
constexpr double kAsinhSoftening = 0.01;

uint8_t to_byte(double v) {
  return uint8_t(std::clamp(std::lround(v), 0L, 255L));
}

// (w - lo) / (hi - lo), also where hi - lo overflows (a range like [-1e308, 1e308]): then in
// halves. A width below the smallest normal double gives +inf for w > lo, clamped to 1 below.
double fraction_of_range(double w, const DensityRange &r) {
  const double width = r.hi - r.lo;
  if (std::isfinite(width)) return (w - r.lo) / width;
  return (0.5 * w - 0.5 * r.lo) / (0.5 * r.hi - 0.5 * r.lo);
}

}  // namespace

DensityRange density_range(const DensityImage &image, const DensityConfig &config) {
  if (config.range) return {(*config.range)[0], (*config.range)[1]};
  int64_t most = 0;
  const size_t ch = size_t(image.channels);
  for (size_t p = 0; p < image.pixel_count(); ++p) most = std::max(most, image.sum[p * ch]);
  const double hi = double(most) / kDensityUnit;
  return {config.transfer == DensityTransfer::kLog ? hi / kLogDecades : 0.0, hi};
}

std::string density_range_problem(const DensityConfig &config) {
  if (!config.range) return {};
  const double lo = (*config.range)[0], hi = (*config.range)[1];
  std::ostringstream range;
  range << "density.range [" << lo << ", " << hi << "]";
  if (!std::isfinite(hi - lo))
    return range.str() +
           " is wider than a double can hold (hi - lo overflows): every pixel maps to about "
           "the same color";
  if (hi - lo < 1.0 / kDensityUnit)
    return range.str() +
           " is narrower than the summed weight's resolution (2^-24 of a particle): every pixel "
           "a footprint reached maps to the top of the range";
  return {};
}

double density_transfer(double w, DensityTransfer transfer, const DensityRange &r) {
  if (!(r.hi > r.lo)) return 0.0;
  const double u = fraction_of_range(w, r);
  double t = 0.0;
  switch (transfer) {
    case DensityTransfer::kLinear:
      t = u;
      break;
    case DensityTransfer::kLog:
      t = w <= r.lo ? 0.0 : std::log(w / r.lo) / std::log(r.hi / r.lo);
      break;
    case DensityTransfer::kAsinh: {
      const double width = r.hi - r.lo, s = kAsinhSoftening * width;
      if (std::isfinite(width) && std::isnormal(s))
        t = std::asinh(std::max(w - r.lo, 0.0) / s) / std::asinh(width / s);
      else  // the same with u, where the width under- or overflows into 0 / 0 or inf / inf
        t = std::asinh(std::max(u, 0.0) / kAsinhSoftening) / std::asinh(1.0 / kAsinhSoftening);
      break;
    }
  }
  // Clamped to [0, 1]; NaN (which std::clamp passes through) is 0.
  return t >= 0.0 ? std::min(t, 1.0) : 0.0;
}

void map_density(const DensityImage &image, const DensityConfig &config, const Colormap &colormap,
                 const uint8_t background[4], Frame *frame) {
  frame->reset(image.width, image.height, background);
  const bool transparent = background[3] == 0;  // background: transparent
  const DensityRange range = density_range(image, config);
  const size_t ch = size_t(image.channels);
  for (size_t p = 0; p < image.pixel_count(); ++p) {
    const int64_t *s = image.sum.data() + p * ch;
    if (s[0] == 0) continue;  // no footprint here: background
    const double t = density_transfer(double(s[0]) / kDensityUnit, config.transfer, range);
    uint8_t *out = frame->rgba.data() + 4 * p;
    if (ch == 1) {
      const Rgb8 c = colormap.at(t, 0.0, 1.0);
      out[0] = c[0], out[1] = c[1], out[2] = c[2];
      out[3] = 255;  // the colormap is the pixel, whatever the background
      continue;
    }
    if (transparent) {  // straight alpha: the mean colour, covering t of the pixel
      for (int k = 0; k < 3; ++k) out[k] = to_byte(256.0 * double(s[1 + k]) / double(s[0]));
      out[3] = to_byte(255.0 * t);
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      // Colour channels hold weight x colour / 256 (core/render/density_splat.h).
      const double mean = 256.0 * double(s[1 + k]) / double(s[0]);
      out[k] = to_byte(background[k] + t * (mean - background[k]));
    }
  }
}

}  // namespace lantern
