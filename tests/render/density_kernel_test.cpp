// The tabulated footprint kernel of style: density (core/render/density_kernel.h): each entry
// sums to exactly 2^16, follows the Gaussian of its sigma and centre, the sigma index is
// round(32 log2(2 sigma)), and the computed kernel beyond the table is normalised.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/render/density_kernel.h"

namespace lantern {
namespace {

constexpr int kWide = 1 << 20;  // an axis no footprint reaches the ends of

int64_t sum_of(const AxisTaps &t) {
  int64_t s = 0;
  for (int i = 0; i < t.count; ++i) s += t.taps[i];
  return s;
}

TEST(DensityKernel, EveryTableEntrySumsToExactlyTwoToTheSixteen) {
  const DensityKernelTable &table = DensityKernelTable::get();
  for (int k = 0; k < kDensitySigmaCount; ++k)
    for (int j = 0; j < kDensityPhases; ++j) {
      AxisTaps t;
      ASSERT_TRUE(table.taps(1000.5 + (j + 0.5) / kDensityPhases, k, kWide, &t));
      ASSERT_EQ(sum_of(t), 1 << kDensityTapBits) << "k " << k << " phase " << j;
      EXPECT_GT(t.taps[0], 0);  // zero taps stripped: no pixel is written for nothing
      EXPECT_GT(t.taps[t.count - 1], 0);
    }
}

TEST(DensityKernel, IndexOfVarianceIsTheRoundedLogOfTwoSigma) {
  const DensityKernelTable &table = DensityKernelTable::get();
  uint32_t h = 99;
  for (int n = 0; n < 100000; ++n) {
    h ^= h << 13, h ^= h >> 17, h ^= h << 5;
    const double sigma = 0.5 * std::exp2(5.0 * double(h) / 4294967296.0);  // 0.5 .. 16 px
    const double exact = 32.0 * std::log2(2.0 * sigma);
    if (std::abs(exact - std::floor(exact) - 0.5) < 1e-9) continue;  // a tie: either is fine
    ASSERT_EQ(table.index_of_variance(sigma * sigma), int(std::lround(exact))) << "sigma " << sigma;
  }
  EXPECT_EQ(table.index_of_variance(0.5 * 0.5), 0);
  EXPECT_EQ(table.index_of_variance(0.3 * 0.3), 0);  // below the pixel filter: the narrowest entry
  EXPECT_EQ(table.index_of_variance(1.0 * 1.0), 32);
  EXPECT_GE(table.index_of_variance(8.0 * 8.0), kDensitySigmaCount);
}

// The taps against the Gaussian of the unquantised sigma and centre, cut at 3 sigma and
// normalised over its samples: the quantisation (2.2 % of sigma, 1/64 px of position) moves a
// tap by a few percent of the peak at most, and the centroid by 1/64 px (plus 0.02 px where the
// shifted centre moves a tap across the 3-sigma cut-off) from the
// unquantised samples' (which the 3-sigma cut-off and the sampling put up to 0.03 px off centre).
TEST(DensityKernel, TapsFollowTheGaussianOfTheirSigmaAndCentre) {
  const DensityKernelTable &table = DensityKernelTable::get();
  for (const double sigma : {0.5, 0.56, 0.9, 1.7, 3.3, 7.5})
    for (const double centre : {500.0, 500.013, 500.31, 500.5, 500.77, 500.99}) {
      AxisTaps t;
      ASSERT_TRUE(table.taps(centre, table.index_of_variance(sigma * sigma), kWide, &t));
      double norm = 0.0, peak = 0.0;
      std::vector<double> g;
      for (int x = int(centre - 5 * sigma) - 2; x <= int(centre + 5 * sigma) + 2; ++x) {
        const double d = x + 0.5 - centre;
        g.push_back(std::abs(d) <= 3.0 * sigma ? std::exp(-d * d / (2 * sigma * sigma)) : 0.0);
        norm += g.back();
      }
      const int x0 = int(centre - 5 * sigma) - 2;
      double ref_centroid = 0.0;  // of the unquantised samples (cut-off and sampling bias it)
      for (size_t i = 0; i < g.size(); ++i) {
        peak = std::max(peak, g[i] /= norm);
        ref_centroid += g[i] * (x0 + int(i) + 0.5);
      }
      double centroid = 0.0;
      for (int i = 0; i < t.count; ++i) {
        const double tap = t.taps[i] / 65536.0;
        const int x = t.first + i;
        ASSERT_GE(x - x0, 0);
        EXPECT_NEAR(tap, g[size_t(x - x0)], 0.05 * peak) << "sigma " << sigma << " x " << x;
        centroid += tap * (x + 0.5);
      }
      EXPECT_NEAR(centroid, ref_centroid, 1.0 / 64.0 + 0.02) << "sigma " << sigma;
      EXPECT_NEAR(centroid, centre, 0.05) << "sigma " << sigma;
    }
}

TEST(DensityKernel, TapsAreClippedToTheAxis) {
  const DensityKernelTable &table = DensityKernelTable::get();
  AxisTaps t;
  ASSERT_TRUE(
      table.taps(0.2, table.index_of_variance(2.0 * 2.0), 100, &t));  // centre near the left end
  EXPECT_EQ(t.first, 0);
  EXPECT_LT(sum_of(t), 65536 * 3 / 4);  // the left part is off the axis
  EXPECT_GT(sum_of(t), 65536 / 2);
  EXPECT_FALSE(table.taps(-10.0, table.index_of_variance(2.0 * 2.0), 100, &t));  // beyond 3 sigma
  EXPECT_FALSE(table.taps(110.0, table.index_of_variance(2.0 * 2.0), 100, &t));
}

TEST(DensityKernel, ComputedTapsBeyondTheTableAreNormalised) {
  std::vector<uint16_t> scratch;
  for (const double sigma : {8.0, 20.0, 90.0}) {
    AxisTaps t;
    ASSERT_TRUE(density_computed_taps(5000.5, sigma, 10000, &scratch, &t));
    EXPECT_NEAR(double(sum_of(t)), 65536.0, 1e-3 * 65536.0) << "sigma " << sigma;
    EXPECT_EQ(t.count, 2 * int(3 * sigma) + 1);
    EXPECT_GT(t.taps[0], 0);  // 2^-16 resolution keeps the 3-sigma tail
  }
  AxisTaps t;
  ASSERT_TRUE(density_computed_taps(3.0, 20.0, 10000, &scratch, &t));  // clipped on the left
  EXPECT_EQ(t.first, 0);
  EXPECT_NEAR(double(sum_of(t)), 65536.0 * 0.56, 0.02 * 65536.0);
}

// place_all's widths at the table's boundaries: for 4 sigma^2 at each boundary 2^((i - 0.5) / 16)
// of every octave of the table (and the octaves around it), one ulp below and one above,
// place_all's k is index_of_variance()'s.
TEST(DensityKernel, PlaceAllFindsTheWidthAtEveryBoundary) {
  const DensityKernelTable &table = DensityKernelTable::get();
  std::vector<double> sigma2;
  for (int octave = -2; octave <= 18; ++octave)
    for (int i = 0; i <= 17; ++i) {
      const double x = std::ldexp(std::exp2((i - 0.5) / 16.0), octave);  // 4 sigma^2
      for (const double v : {std::nextafter(x, 0.0), x, std::nextafter(x, HUGE_VAL)})
        sigma2.push_back(v / 4.0);
    }
  const std::vector<double> px(sigma2.size(), 50.5), py(sigma2.size(), 40.25);
  DensityPlacements all;
  table.place_all(px.data(), py.data(), sigma2.data(), int(sigma2.size()), 100, 100, &all);
  int steps = 0;
  for (size_t i = 0; i < sigma2.size(); ++i) {
    ASSERT_EQ(all.k[i], table.index_of_variance(sigma2[i])) << i << " sigma2 " << sigma2[i];
    steps += i > 0 && all.k[i] != all.k[i - 1];
  }
  EXPECT_GT(steps, kDensitySigmaCount);  // every boundary of the table steps k
}

// Expects place_all() of the footprints to give index_of_variance(), then place() and taps_at()
// per axis on a width x height image, footprint by footprint; counts those on the image and those
// beyond the table.
void expect_placed_one_by_one(const std::vector<double> &px, const std::vector<double> &py,
                              const std::vector<double> &sigma2, int width, int height, int *on,
                              int *wide) {
  const DensityKernelTable &table = DensityKernelTable::get();
  DensityPlacements all;
  table.place_all(px.data(), py.data(), sigma2.data(), int(px.size()), width, height, &all);
  for (size_t i = 0; i < px.size(); ++i) {
    const int k = table.index_of_variance(sigma2[i]);
    ASSERT_EQ(all.k[i], k) << i;
    if (k >= kDensitySigmaCount) {
      ++*wide;
      continue;
    }
    bool touches = std::abs(px[i]) < double(1 << 30) && std::abs(py[i]) < double(1 << 30);
    AxisTaps ax, ay;
    touches = touches && table.taps(px[i], k, width, &ax) && table.taps(py[i], k, height, &ay);
    ASSERT_EQ(all.count_x[i] > 0, touches) << i;
    if (!touches) continue;
    ++*on;
    ASSERT_EQ(table.tap_data() + all.taps_x[i], ax.taps) << i;
    ASSERT_EQ(table.tap_data() + all.taps_y[i], ay.taps) << i;
    ASSERT_EQ(all.first_x[i], ax.first) << i;
    ASSERT_EQ(all.first_y[i], ay.first) << i;
    ASSERT_EQ(all.count_x[i], ax.count) << i;
    ASSERT_EQ(all.count_y[i], ay.count) << i;
  }
}

// place_all (the vectorised look-ups of a batch) gives index_of_variance(), then place() and
// taps_at() per axis, integer for integer: for widths across the table and beyond it, centres
// on, beside and far off the image, and non-finite ones; a count that is not a multiple of the
// vector width.
TEST(DensityKernel, PlaceAllIsPlaceAndTapsAtOneByOne) {
  uint32_t h = 4242;
  const auto next = [&h] {
    h ^= h << 13, h ^= h >> 17, h ^= h << 5;
    return double(h) / 4294967296.0;
  };
  constexpr int kWidth = 300, kHeight = 200;
  std::vector<double> px, py, sigma2;
  for (int n = 0; n < 5003; ++n) {
    px.push_back(340.0 * next() - 20.0), py.push_back(240.0 * next() - 20.0);
    const double sigma = 0.4 * std::exp2(6.0 * next());  // 0.4 .. 25.6 px: table and beyond
    sigma2.push_back(sigma * sigma);
    switch (n % 97) {
      case 1:
        px.back() = std::nan("");
        break;
      case 2:
        py.back() = HUGE_VAL;
        break;
      case 3:
        px.back() = -3e9;
        break;
      case 4:
        py.back() = double(1 << 30);
        break;
      case 5:
        sigma2.back() = std::nan("");
        break;
      case 6:
        sigma2.back() = 0.25;
        break;  // sigma 0.5: k 0 exactly
      case 7:
        sigma2.back() = 1e300;
        break;
      default:
        break;
    }
  }
  int on = 0, wide = 0;
  expect_placed_one_by_one(px, py, sigma2, kWidth, kHeight, &on, &wide);
  EXPECT_GT(on, 2500);
  EXPECT_GT(wide, 500);
}

// place_all on widths that vary slowly along the batch, as a published order's do (most
// vectors of 8 share one k, which place_all then takes from the last vector's range): the
// same integers one by one, with every boundary of the table met exactly, just below and just
// above, and non-finite, negative and huge widths among them.
TEST(DensityKernel, PlaceAllOfSlowlyVaryingWidthsIsPlaceOneByOne) {
  std::vector<double> px, py, sigma2;
  double x = 0.5;  // 4 sigma^2, from sigma 0.35 to beyond the table
  for (int n = 0; x < 400.0; ++n) {
    px.push_back(20.0 + 0.37 * (n % 700)), py.push_back(30.0 + 0.011 * n);
    sigma2.push_back(x / 4.0);
    x *= 1.0007;
    switch (n % 2003) {
      case 11:
        sigma2.back() = std::nan("");
        break;
      case 12:
        sigma2.back() = -1.0;
        break;
      case 13:
        sigma2.back() = 1e300;
        break;
      default:
        break;
    }
    if (n % 61 == 0) {  // the boundary at or just above x, met exactly and beside it
      const double b = std::exp2(std::ceil(16.0 * std::log2(x) - 0.5) / 16.0 + 0.5 / 16.0);
      for (const double v : {std::nextafter(b, 0.0), b, std::nextafter(b, HUGE_VAL)}) {
        px.push_back(px.back()), py.push_back(py.back());
        sigma2.push_back(v / 4.0);
      }
    }
  }
  int on = 0, wide = 0;
  expect_placed_one_by_one(px, py, sigma2, 300, 200, &on, &wide);
  EXPECT_GT(on, 8000);
  EXPECT_GT(wide, 500);
}

}  // namespace
}  // namespace lantern
