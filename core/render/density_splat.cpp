#include "core/render/density_splat.h"

#include <algorithm>
#include <cmath>

namespace lantern {
namespace {

constexpr double kCutoffSigmas = 3.0;
constexpr double kPixelFilterSigma = 0.5;  // px: the reconstruction filter every footprint gets
// From this sigma (px) on, an axis is normalised by the analytic integral of the truncated
// Gaussian, not by summing every tap (which may lie far off the image).
constexpr double kAnalyticFromSigma = 8.0;

// Integral over [-3 sigma, 3 sigma] of exp(-x^2 / (2 sigma^2)), per unit sigma.
double truncated_integral_per_sigma() {
  static const double v = std::sqrt(2.0 * M_PI) * std::erf(kCutoffSigmas / std::sqrt(2.0));
  return v;
}

}  // namespace

DensitySplatter::DensitySplatter(const ViewGeometry &g, DensityImage *image)
    : g_(g), image_(image) {}

bool DensitySplatter::axis(double centre, double sigma, int size, std::vector<double> *taps,
                           int *first, int *last) const {
  const double reach = kCutoffSigmas * sigma;
  // Pixel k (centre k + 0.5) is inside the cut-off when |k + 0.5 - centre| <= reach. Clamped in
  // double before converting, so a huge footprint cannot overflow int.
  const double lo_d = std::ceil(centre - 0.5 - reach), hi_d = std::floor(centre - 0.5 + reach);
  if (hi_d < 0.0 || lo_d > double(size - 1) || lo_d > hi_d) return false;
  const double a = 0.5 / (sigma * sigma);
  const int lo = int(std::max(lo_d, 0.0)), hi = int(std::min(hi_d, double(size - 1)));
  // Taps from pixel `from` on by the Gaussian's recurrence: g(t + 1) = g(t) q(t) with
  // q(t) = exp(-(2t + 1) a) and q(t + 1) = q(t) exp(-2a) - three exps per axis instead of one per
  // tap (the splat's cost is in its exps and its pixels).
  const auto fill = [&](double from, size_t n, double *out) {
    const double t = from + 0.5 - centre;
    double g = std::exp(-t * t * a), q = std::exp(-(2.0 * t + 1.0) * a);
    const double qq = std::exp(-2.0 * a);
    for (size_t k = 0; k < n; ++k) out[k] = g, g *= q, q *= qq;
  };
  double norm = 0.0;
  size_t skip = 0;                   // taps of the full kernel left of the image
  if (sigma < kAnalyticFromSigma) {  // at most 2 * 24 + 1 taps: sum them all, on or off the image
    const auto all = size_t(hi_d - lo_d + 1.0);
    taps->resize(all);
    fill(lo_d, all, taps->data());
    for (const double v : *taps) norm += v;
    skip = size_t(double(lo) - lo_d);
  } else {
    norm = sigma * truncated_integral_per_sigma();
    taps->resize(size_t(hi - lo + 1));
    fill(double(lo), taps->size(), taps->data());
  }
  const double inv_norm = 1.0 / norm;
  const auto n = size_t(hi - lo + 1);
  for (size_t k = 0; k < n; ++k) (*taps)[k] = (*taps)[k + skip] * inv_norm;
  taps->resize(n);
  *first = lo, *last = hi;
  return true;
}

bool DensitySplatter::splat(const glm::dvec3 &c, double r, double weight, const Rgb8 &color) {
  const double d = -c.z;
  if (!(d > g_.near_plane)) return false;
  const double x_ndc = g_.orthographic ? g_.sx * c.x + g_.tx : g_.sx * c.x / d;
  const double y_ndc = g_.orthographic ? g_.sy * c.y + g_.ty : g_.sy * c.y / d;
  const double px = 0.5 * (x_ndc + 1.0) * g_.width;
  const double py = 0.5 * (1.0 - y_ndc) * g_.height;
  const double s = r / kCutoffSigmas * g_.pixels_per_unit(d);
  const double sigma = std::sqrt(s * s + kPixelFilterSigma * kPixelFilterSigma);
  int x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  if (!axis(px, sigma, g_.width, &gx_, &x0, &x1) || !axis(py, sigma, g_.height, &gy_, &y0, &y1))
    return false;
  pixels_written_ += int64_t(x1 - x0 + 1) * (y1 - y0 + 1);
  const double scale = weight * kDensityUnit;
  const int ch = image_->channels;
  const uint64_t c0 = color[0], c1 = color[1], c2 = color[2];
  for (int y = y0; y <= y1; ++y) {
    // Shares are >= 0: adding 0.5 and truncating rounds (inline, unlike llrint).
    const double row = scale * gy_[size_t(y - y0)];
    int64_t *out = image_->sum.data() + (size_t(y) * size_t(g_.width) + size_t(x0)) * size_t(ch);
    const double *gx = gx_.data();
    const int n = x1 - x0 + 1;
    if (ch == 1) {
      for (int i = 0; i < n; ++i) out[i] += int64_t(row * gx[i] + 0.5);
      continue;
    }
    for (int i = 0; i < n; ++i, out += 4) {
      const auto q = uint64_t(row * gx[i] + 0.5);
      // Rounded q * c / 255 (unsigned: a multiply and a shift): each colour share is at most the
      // weight share.
      out[0] += int64_t(q);
      out[1] += int64_t((q * c0 + 127) / 255);
      out[2] += int64_t((q * c1 + 127) / 255);
      out[3] += int64_t((q * c2 + 127) / 255);
    }
  }
  return true;
}

}  // namespace lantern
