// scan_particles: its fast path (one radius, no scalar) agrees with Extent::add_particle
// particle by particle, for every position layout, including non-finite positions.
#include "core/particles/particle_scan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "tests/support/extent_expect.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

Extent reference(const ParticleArrays &p, double radius) {
  Extent e;
  for (int64_t i = 0; i < p.count(); ++i) {
    const glm::dvec3 x = p.position(i);
    e.add_particle(x.x, x.y, x.z, radius);
  }
  return e;
}

// scan_particles of the packed doubles `xyz` on each thread count against the one-pass
// reference: the same values and counts, and the same sign where a bound is zero.
void expect_one_pass_bits(std::vector<double> &xyz, std::initializer_list<int> thread_counts,
                          const std::string &what) {
  ParticleDescription p{};
  p.count = int64_t(xyz.size() / 3);
  p.position = {xyz.data(), DataType::kFloat64, 0};
  ParticleArrays a;
  ASSERT_OK(ParticleArrays::validate(p, &a));
  const Extent want = reference(a, 0.5);
  for (const int threads : thread_counts) {
    SCOPED_TRACE(what + ", threads " + std::to_string(threads));
    const Extent got = scan_particles(a, false, 0.5, threads);
    expect_same_extent(got, want);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(std::signbit(got.lo[k]), std::signbit(want.lo[k])) << "lo " << k;
      EXPECT_EQ(std::signbit(got.hi[k]), std::signbit(want.hi[k])) << "hi " << k;
    }
  }
}

TEST(ParticleScan, FastPathMatchesAddParticleForEveryLayout) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-50.0, 80.0);
  const size_t n = 5000;
  std::vector<double> xyz(3 * n), x(n), y(n), z(n);
  std::vector<float> xyzf(3 * n);
  for (size_t i = 0; i < 3 * n; ++i) xyz[i] = u(rng);
  xyz[30] = std::numeric_limits<double>::quiet_NaN();  // particle 10
  xyz[301] = std::numeric_limits<double>::infinity();  // particle 100
  for (size_t i = 0; i < n; ++i) x[i] = xyz[3 * i], y[i] = xyz[3 * i + 1], z[i] = xyz[3 * i + 2];
  for (size_t i = 0; i < 3 * n; ++i) xyzf[i] = float(xyz[i]);
  for (int layout = 0; layout < 4; ++layout) {
    ParticleDescription p{};
    p.count = int64_t(layout == 3 ? 0 : n);
    if (layout == 0 || layout == 3) p.position = {xyz.data(), DataType::kFloat64, 0};
    if (layout == 1) p.position = {xyzf.data(), DataType::kFloat32, 0};
    if (layout == 2) {
      p.position_x = {x.data(), DataType::kFloat64, 0};
      p.position_y = {y.data(), DataType::kFloat64, 0};
      p.position_z = {z.data(), DataType::kFloat64, 0};
    }
    ParticleArrays a;
    ASSERT_OK(ParticleArrays::validate(p, &a)) << "layout " << layout;
    for (const double radius : {0.5, std::numeric_limits<double>::quiet_NaN()}) {
      const Extent fast = scan_particles(a, false, radius);
      expect_same_extent(fast, reference(a, radius));
      if (layout < 3) EXPECT_EQ(fast.nonfinite_count, 2) << "layout " << layout;
    }
  }
}

// -0 and +0 are equal but encoded apart: a one-pass min or max keeps the first zero it meets.
// The fast path (lanes, parts on threads) must give exactly those bits.
TEST(ParticleScan, ZeroBoundsAndThreadsGiveTheOnePassBits) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(0.0, 9.0);
  const size_t n = 300000;
  for (int trial = 0; trial < 8; ++trial) {
    std::vector<double> xyz(3 * n);
    for (double &v : xyz) v = u(rng);
    // Zeros of random signs at the low end of x and z, and at the high end of y (all y <= 0).
    for (size_t i = 0; i < n; ++i) xyz[3 * i + 1] = -xyz[3 * i + 1];
    for (int k = 0; k < 50; ++k) {
      const size_t i = rng() % n;
      xyz[3 * i + size_t(k % 3)] = rng() % 2 ? -0.0 : 0.0;
    }
    xyz[3 * (rng() % n)] = std::numeric_limits<double>::quiet_NaN();
    expect_one_pass_bits(xyz, {1, 2, 3, 7}, "trial " + std::to_string(trial));
  }
}

// Packed doubles go eight at a time through a vector path where the CPU has AVX2: every count
// (whole blocks and tails), a non-finite coordinate at each place of a block, infinities of both
// signs, the largest finite values and subnormals must give the one-pass bits and counts.
TEST(ParticleScan, PackedBlocksGiveTheOnePassBitsForEveryShape) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  const double inf = std::numeric_limits<double>::infinity();
  const double specials[] = {std::numeric_limits<double>::quiet_NaN(),
                             inf,
                             -inf,
                             std::numeric_limits<double>::max(),
                             -std::numeric_limits<double>::max(),
                             std::numeric_limits<double>::denorm_min(),
                             -0.0,
                             0.0};
  for (size_t n = 0; n <= 41; ++n)
    for (int trial = 0; trial < 24; ++trial) {
      std::vector<double> xyz(3 * n);
      for (double &v : xyz) v = u(rng);
      const int odd_ones = trial % 4;
      for (int k = 0; k < odd_ones && n > 0; ++k)
        xyz[rng() % (3 * n)] = specials[rng() % (sizeof specials / sizeof specials[0])];
      expect_one_pass_bits(xyz, {1, 3},
                           "n " + std::to_string(n) + " trial " + std::to_string(trial));
    }
}

}  // namespace
}  // namespace lantern
