#include "core/render/density_kernel.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

namespace lantern {
namespace {

constexpr double kCutoffSigmas = 3.0;
constexpr int kTapSum = 1 << kDensityTapBits;

// The samples of one table entry, scaled to integers summing to exactly 2^16 (largest
// remainder), zero taps stripped. Returns the first tap's pixel offset from floor(c - 0.5).
int table_entry(double sigma, double phase, std::vector<uint16_t> *out) {
  const double reach = kCutoffSigmas * sigma;
  const int lo = int(std::ceil(phase - reach)), hi = int(std::floor(phase + reach));
  std::vector<double> g;
  for (int t = lo; t <= hi; ++t)
    g.push_back(std::exp(-(t - phase) * (t - phase) / (2 * sigma * sigma)));
  const double total = std::accumulate(g.begin(), g.end(), 0.0);
  std::vector<uint32_t> tap(g.size());
  std::vector<double> frac(g.size());
  int64_t given = 0;
  for (size_t i = 0; i < g.size(); ++i) {
    const double v = g[i] / total * kTapSum;
    tap[i] = uint32_t(std::floor(v));
    frac[i] = v - std::floor(v);
    given += tap[i];
  }
  std::vector<size_t> order(g.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return frac[a] > frac[b]; });
  for (int64_t r = 0; r < kTapSum - given; ++r) ++tap[order[size_t(r) % order.size()]];
  size_t first = 0, last = tap.size();
  while (first < last && tap[first] == 0) ++first;
  while (last > first && tap[last - 1] == 0) --last;
  for (size_t i = first; i < last; ++i) out->push_back(uint16_t(tap[i]));
  return lo + int(first);
}

// The unquantised truncated Gaussian beyond the table, over the pixels on the image only.
}  // namespace

DensityKernelTable::DensityKernelTable() {
  for (int k = 0; k < kDensitySigmaCount; ++k) {
    const double sigma = 0.5 * std::exp2(double(k) / kDensitySigmaSteps);
    for (int j = 0; j < kDensityPhases; ++j) {
      Entry e;
      e.offset = uint32_t(taps_.size());
      e.first = int16_t(table_entry(sigma, (j + 0.5) / kDensityPhases, &taps_));
      e.count = uint16_t(taps_.size() - e.offset);
      entries_.push_back(e);
    }
  }
  // Boundaries of 4 sigma^2 within one octave [1, 2), then the next octave's first: sigma's
  // 32 steps per octave are 16 per octave of its square.
  constexpr int kSteps = kDensitySigmaSteps / 2;
  std::vector<double> bounds;
  for (int i = 1; i <= kSteps + 1; ++i) bounds.push_back(std::exp2((i - 0.5) / kSteps));
  for (int bin = 0; bin < 1024; ++bin) {
    const double start = 1.0 + bin / 1024.0;
    const auto n = std::upper_bound(bounds.begin(), bounds.end(), start) - bounds.begin();
    below_.push_back(uint8_t(n));
    next_.push_back(bounds[size_t(n)]);
  }
}

const DensityKernelTable &DensityKernelTable::get() {
  static const DensityKernelTable t;
  return t;
}

bool density_computed_taps(double centre, double sigma, int size, std::vector<uint16_t> *scratch,
                           AxisTaps *out) {
  const double reach = kCutoffSigmas * sigma;
  // Pixel k (centre k + 0.5) is inside the cut-off when |k + 0.5 - centre| <= reach. Clamped in
  // double before converting, so a huge footprint cannot overflow int.
  const double lo_d = std::ceil(centre - 0.5 - reach), hi_d = std::floor(centre - 0.5 + reach);
  if (hi_d < 0.0 || lo_d > double(size - 1) || lo_d > hi_d) return false;
  const int lo = int(std::max(lo_d, 0.0)), hi = int(std::min(hi_d, double(size - 1)));
  static const double integral_per_sigma =
      std::sqrt(2.0 * M_PI) * std::erf(kCutoffSigmas / std::sqrt(2.0));
  const double scale = kTapSum / (sigma * integral_per_sigma);
  const double a = 0.5 / (sigma * sigma);
  // Taps by the Gaussian's recurrence g(t + 1) = g(t) q(t), q(t + 1) = q(t) exp(-2a): three exps
  // per axis instead of one per tap.
  const double t = lo + 0.5 - centre;
  double g = std::exp(-t * t * a) * scale, q = std::exp(-(2.0 * t + 1.0) * a);
  const double qq = std::exp(-2.0 * a);
  scratch->resize(size_t(hi - lo + 1));
  for (uint16_t &v : *scratch) v = uint16_t(std::min(g + 0.5, 65535.0)), g *= q, q *= qq;
  out->taps = scratch->data();
  out->first = lo;
  out->count = hi - lo + 1;
  return true;
}

}  // namespace lantern
