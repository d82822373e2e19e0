// The footprint kernel of `style: density` along one image axis, in fixed point: what
// core/render/density_splat.h multiplies, per pixel, into a particle's share. The kernel is
// *defined* by the integer taps below (not by a Gaussian evaluated per particle): every particle
// of the same quantised width and sub-pixel phase gets the same taps, so no exp is evaluated per
// particle and each axis sums to exactly 2^16.
//
// One axis, footprint centre c (pixel units, pixel k's centre at k + 0.5), width sigma (px,
// sigma >= 0.5: the pixel filter alone is 0.5):
//   - Tabulated, for sigma < 0.5 * 2^(127.5 / 32) = 7.915 px: sigma is quantised
//     logarithmically to sigma_k = 0.5 * 2^(k / 32), k = round(32 log2(2 sigma)) in [0, 128)
//     (2.2 % steps), and the centre's sub-pixel phase to 1/32 px: with u = c - 0.5,
//     b = floor(u), j = floor(32 (u - b)), the centre is taken at b + (j + 0.5) / 32
//     (so a position error of at most 1/64 px). The taps of entry (k, j) are the samples
//     exp(-t'^2 / (2 sigma_k^2)) at the pixel centres t' = t - (j + 0.5) / 32 within
//     |t'| <= 3 sigma_k, scaled to integers that sum to exactly 2^16 (each sample's floor, the
//     remainder handed out one unit at a time by largest fractional part, ties to the lower
//     pixel), and stripped of zero taps at both ends. 128 x 32 entries, about 150 kB, built
//     once per process.
//   - Computed, for larger sigma: the same truncated Gaussian (3 sigma cut-off, unquantised
//     centre and sigma), each tap round(2^16 g(t') / I) with I the analytic integral of the
//     truncated Gaussian (within 0.1 % of the taps' sum from sigma 7.9 on), evaluated only over
//     the pixels on the image.
// A footprint whose taps all lie off the image (or a non-finite centre) has none.
//
// Thread-safety: the table is immutable once built (a function-local static); AxisTaps borrows
// either the table or the caller's scratch.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace lantern {

inline constexpr int kDensityTapBits = 16;      // each axis's taps sum to 2^16 (tabulated exactly)
inline constexpr int kDensitySigmaSteps = 32;   // table steps per octave of sigma
inline constexpr int kDensitySigmaCount = 128;  // table sigmas: 0.5 .. 0.5 * 2^(127 / 32)
inline constexpr int kDensityPhases = 32;       // sub-pixel phases per pixel

// The taps of one axis on the image: pixel indices first .. first + count - 1, each with weight
// taps[i] / 2^16.
struct AxisTaps {
  const uint16_t *taps = nullptr;
  int first = 0;
  int count = 0;
};

// Where a batch of footprints lands (DensityKernelTable::place_all), one array per quantity:
// per footprint its table width k (kDensitySigmaCount or more: beyond the table, nothing else
// set), and for a table footprint its taps per axis on the image (offset into the table's
// taps, first pixel, count; count_x 0: no tap on the image, or a centre 2^30 px or more away).
struct DensityPlacements {
  std::vector<int32_t> k, first_x, first_y, count_x, count_y;
  std::vector<uint32_t> taps_x, taps_y;
  void resize(size_t n) {
    for (std::vector<int32_t> *v : {&k, &first_x, &first_y, &count_x, &count_y}) v->resize(n);
    taps_x.resize(n), taps_y.resize(n);
  }
};

// The table of the header comment.
class DensityKernelTable {
 public:
  // The process's table (built on first use; thread-safe).
  static const DensityKernelTable &get();

  // k of the header for a width of variance `sigma2` = sigma^2 (px^2): the number of
  // boundaries 2^((i - 0.5) / 16), i >= 1, at or below 4 sigma^2, which is round(32 log2(2 sigma))
  // found from the bits of 4 sigma^2, without a square root or a log; 0 below sigma 0.5;
  // kDensitySigmaCount or more: beyond the table. Inline: it runs for every particle.
  int index_of_variance(double sigma2) const {
    const double x = 4.0 * sigma2;
    if (!(x >= 1.0)) return 0;
    if (!(x < 65536.0)) return kDensitySigmaCount;
    uint64_t bits = 0;
    std::memcpy(&bits, &x, sizeof bits);
    const int octave = int(bits >> 52) - 1023;
    const auto bin = size_t((bits >> 42) & 1023);
    bits = (bits & ((uint64_t(1) << 52) - 1)) | (uint64_t(1023) << 52);  // mantissa in [1, 2)
    double m = 0.0;
    std::memcpy(&m, &bits, sizeof m);
    return kDensitySigmaSteps / 2 * octave + below_[bin] + (m >= next_[bin]);
  }

  // The pixel base floor(centre - 0.5) and sub-pixel phase j of `centre` (the header's b and
  // j); `centre` must be finite and within 2^30 px of the image.
  static void place(double centre, int *base, int *phase) {
    const double u = centre - 0.5, b = std::floor(u);
    *phase = std::min(int((u - b) * kDensityPhases), kDensityPhases - 1);
    *base = int(b);
  }

  // The taps of entry (k, phase) at pixel base `base` on [0, size); false when none lies there.
  bool taps_at(int base, int phase, int k, int size, AxisTaps *out) const {
    const Entry &e = entries_[size_t(k) * kDensityPhases + size_t(phase)];
    const int lo = base + e.first, hi = lo + int(e.count) - 1;
    if (hi < 0 || lo > size - 1) return false;
    const int a = std::max(lo, 0), z = std::min(hi, size - 1);
    out->taps = taps_.data() + e.offset + (a - lo);
    out->first = a;
    out->count = z - a + 1;
    return true;
  }

  // For footprints [0, count) (centres px, py, variances sigma2): index_of_variance(), then
  // for table widths the centre's farness test, place() and taps_at() per axis on a
  // width x height image, into `out` (resized). The same integers as those calls; vectorised
  // (AVX-512) where the processor has it: on fcc 10 M at 1024^2 these per-particle look-ups,
  // one particle at a time, took about a quarter of the splat.
  void place_all(const double *px, const double *py, const double *sigma2, int count, int width,
                 int height, DensityPlacements *out) const;
  // The taps that DensityPlacements' offsets index.
  const uint16_t *tap_data() const { return taps_.data(); }

  // The taps of entry (k, phase of `centre`) on [0, size): place() then taps_at().
  bool taps(double centre, int k, int size, AxisTaps *out) const {
    int base = 0, phase = 0;
    place(centre, &base, &phase);
    return taps_at(base, phase, k, size, out);
  }

 private:
  DensityKernelTable();
  struct Entry {
    uint32_t offset = 0;  // into taps_
    int16_t first = 0;    // first tap's pixel, from floor(centre - 0.5)
    uint16_t count = 0;
  };
  std::vector<uint16_t> taps_;
  std::vector<Entry> entries_;  // k * kDensityPhases + phase
  // Per 1/1024 of an octave of 4 sigma^2's mantissa: the boundaries below the bin, and the one
  // boundary that may fall inside it (at most one: bins are 1/710 of an octave wide at most,
  // boundaries 1/16).
  std::vector<uint8_t> below_;
  std::vector<double> next_;
  std::vector<int32_t> below32_;  // below_ widened, for a vector gather
  // starts_[k]: the least 4 sigma^2 whose index_of_variance() is k (k <= kDensitySigmaCount);
  // starts_[0] is minus infinity.
  std::vector<double> starts_;
  void place_range(const double *px, const double *py, const double *sigma2, int from, int to,
                   int width, int height, DensityPlacements *out) const;
};

// The taps of a footprint of centre `centre` and width `sigma` beyond the table (k >=
// kDensitySigmaCount) on the pixels [0, size); false when none lies there. `scratch` holds the
// taps and must outlive `out`'s use.
bool density_computed_taps(double centre, double sigma, int size, std::vector<uint16_t> *scratch,
                           AxisTaps *out);

}  // namespace lantern
