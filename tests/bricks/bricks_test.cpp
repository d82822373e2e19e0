// Bricks: Morton keys, the radix sort, brick bounds and the level layout's uniform prefixes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <glm/common.hpp>

#include "core/bricks/brick_set.h"
#include "core/bricks/level_layout.h"
#include "core/bricks/morton.h"
#include "core/bricks/radix_sort.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

// Interleaves bits the slow, obvious way.
uint64_t reference_morton(uint32_t x, uint32_t y, uint32_t z) {
  uint64_t k = 0;
  for (int b = 0; b < 21; ++b) {
    k |= uint64_t((x >> b) & 1) << (3 * b + 2);
    k |= uint64_t((y >> b) & 1) << (3 * b + 1);
    k |= uint64_t((z >> b) & 1) << (3 * b);
  }
  return k;
}

ParticleArrays borrow(const std::vector<double> &xyz, const std::vector<float> *radius = nullptr) {
  ParticleDescription p{};
  p.count = int64_t(xyz.size() / 3);
  p.position = {xyz.data(), DataType::kFloat64, 0};
  if (radius) p.radius = {radius->data(), DataType::kFloat32, 0};
  ParticleArrays a;
  EXPECT_OK(ParticleArrays::validate(p, &a));
  return a;
}

std::vector<double> random_points(size_t n, unsigned seed, double lo = -3.0, double hi = 5.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> xyz(3 * n);
  for (double &v : xyz) v = u(rng);
  return xyz;
}

TEST(Morton, MatchesBitByBitInterleaving) {
  std::mt19937 rng(1);
  for (int t = 0; t < 10000; ++t) {
    const uint32_t x = rng() & kMortonAxisMax, y = rng() & kMortonAxisMax,
                   z = rng() & kMortonAxisMax;
    const uint64_t k = morton_encode(x, y, z);
    ASSERT_EQ(k, reference_morton(x, y, z));
    EXPECT_EQ(morton_compact3(k >> 2), x);
    EXPECT_EQ(morton_compact3(k >> 1), y);
    EXPECT_EQ(morton_compact3(k), z);
  }
  EXPECT_EQ(morton_encode(kMortonAxisMax, kMortonAxisMax, kMortonAxisMax), (uint64_t(1) << 63) - 1);
}

TEST(Morton, PrefixIsTheKeysTop32Bits) {
  std::mt19937 rng(5);
  for (int t = 0; t < 100000; ++t) {
    const uint32_t x = rng() & kMortonAxisMax, y = rng() & kMortonAxisMax,
                   z = rng() & kMortonAxisMax;
    ASSERT_EQ(morton_prefix(x, y, z), uint32_t(reference_morton(x, y, z) >> 31))
        << x << " " << y << " " << z;
  }
  EXPECT_EQ(morton_prefix(kMortonAxisMax, kMortonAxisMax, kMortonAxisMax), 0xffffffffu);
  EXPECT_EQ(morton_prefix(1023, 1023, 2047), 0u);  // bits below the prefix's
}

// Bounds whose longest side is denormal: kMortonAxisMax / side overflowed, and a point on the
// low face had 0 x inf = NaN as its lattice coordinate (converted to an integer: undefined).
TEST(Morton, BoundsTooSmallForAFiniteScaleGiveKeyZero) {
  const double tiny = 1e-310;
  const MortonQuantiser q = MortonQuantiser::for_bounds({0.0, 0.0, 0.0}, {tiny, 0.0, 0.0});
  EXPECT_TRUE(std::isfinite(q.scale));
  EXPECT_EQ(q.key({0.0, 0.0, 0.0}), 0u);
  EXPECT_EQ(q.key({tiny, 0.0, 0.0}), 0u);
  // And a NaN coordinate (never from finite bounds and points) is the low end, not a conversion.
  const MortonQuantiser unit = MortonQuantiser::for_bounds(glm::dvec3(0.0), glm::dvec3(1.0));
  EXPECT_EQ(unit.axis(std::numeric_limits<double>::quiet_NaN(), 0.0), 0u);
  EXPECT_EQ(unit.axis(1.0, 0.0), kMortonAxisMax);
}

// The four-at-a-time prefix (SSE2 where built with it) against the scalar one, point by point:
// inside the box, outside it on both sides (clamped), on its faces, on lattice steps and their
// neighbours (truncation), and at the largest and smallest coordinates.
TEST(Morton, FourPrefixesAtOnceAreTheScalarPrefixes) {
  const MortonQuantiser q = MortonQuantiser::for_bounds({-3.0, 0.0, 1e-3}, {5.0, 2.0, 7.0});
  std::vector<double> v;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-12.0, 14.0);
  for (int t = 0; t < 40000; ++t) v.push_back(u(rng));
  for (int k = 0; k <= 2048; ++k) {  // the lattice steps that change the top 11 bits, and between
    const double step = 8.0 * double(k) * 1024.0 / double(kMortonAxisMax);
    for (const double o : {-3.0, 0.0, 1e-3})
      for (const double d : {-1e-12, 0.0, 1e-12}) v.push_back(o + step + d);
  }
  for (const double e :
       {-3.0, 5.0, 0.0, -0.0, 2.0, 7.0, 1e-3, 1e300, -1e300,
        std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
        std::numeric_limits<double>::denorm_min(), 4.999999999999999})
    v.push_back(e);
  std::shuffle(v.begin(), v.end(), rng);
  while (v.size() % 12) v.push_back(1.0);
  for (size_t i = 0; i + 12 <= v.size(); i += 12) {
    const double *x = &v[i], *y = &v[i + 4], *z = &v[i + 8];
    uint32_t out[4];
    q.prefix4(x, y, z, out);
    for (int k = 0; k < 4; ++k)
      ASSERT_EQ(out[k], q.prefix({x[k], y[k], z[k]})) << x[k] << " " << y[k] << " " << z[k];
  }
}

// Packed xyz doubles (the brick build's first pass), with each kernel the processor has (AVX-512,
// AVX2, prefix4): every prefix the scalar one, over counts that leave tails of 0-7 points, and -0
// reported exactly when some coordinate is -0 (in any lane of the vector part, or the tail).
TEST(Morton, PackedPrefixesAreTheScalarPrefixes) {
  const MortonQuantiser q = MortonQuantiser::for_bounds({-3.0, 0.0, 1e-3}, {5.0, 2.0, 7.0});
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-12.0, 14.0);
  std::vector<double> xyz(3 * 4099);
  for (double &v : xyz) v = u(rng);
  for (int k = 0; k <= 2048; k += 7) xyz[size_t(k) * 3 % xyz.size()] = -3.0 + 8.0 * k / 2048.0;
  xyz[5] = 1e300, xyz[6] = -std::numeric_limits<double>::infinity(), xyz[7] = 0.0;
  const PrefixKernel kernels[] = {PrefixKernel::kWidest, PrefixKernel::kAvx2,
                                  PrefixKernel::kPrefix4};
  for (const int64_t count : {0, 1, 3, 4, 5, 7, 8, 9, 15, 16, 17, 4096, 4099}) {
    for (const PrefixKernel kernel : kernels) {
      std::vector<uint32_t> out(static_cast<size_t>(count) + 1, 0xdeadbeefu);
      EXPECT_FALSE(packed_prefixes(q, xyz.data(), count, out.data(), kernel));
      for (int64_t i = 0; i < count; ++i) {
        const double *p = &xyz[size_t(3 * i)];
        ASSERT_EQ(out[size_t(i)], q.prefix({p[0], p[1], p[2]})) << i << " of " << count;
      }
      EXPECT_EQ(out[size_t(count)], 0xdeadbeefu);  // nothing written past the last
    }
  }
  for (const size_t at : {0, 4, 11, 17, 22, 23, 24, 3 * 4096 + 1}) {
    std::vector<double> signed_zero = xyz;
    signed_zero[at] = -0.0;
    std::vector<uint32_t> out(4099);
    for (const PrefixKernel kernel : kernels) {
      EXPECT_TRUE(packed_prefixes(q, signed_zero.data(), 4099, out.data(), kernel)) << at;
      EXPECT_EQ(out[at / 3], q.prefix({signed_zero[at / 3 * 3], signed_zero[at / 3 * 3 + 1],
                                       signed_zero[at / 3 * 3 + 2]}));
    }
  }
}

TEST(RadixSort, MatchesStdSortOnFullAndPartialBitRanges) {
  std::mt19937_64 rng(2);
  for (const size_t n : {size_t(0), size_t(1), size_t(7), size_t(1000), size_t(200000)}) {
    PageVector<uint64_t> words(n);
    for (auto &w : words) w = rng() >> (rng() % 40);  // varied magnitudes, shared top bits
    PageVector<uint64_t> full = words, scratch;
    radix_sort_words(&full, &scratch, 0, 64);
    PageVector<uint64_t> expect = words;
    std::sort(expect.begin(), expect.end());
    EXPECT_EQ(full, expect);
    // Upper half only: stable, so equal upper halves keep their input order.
    PageVector<uint64_t> upper = words;
    radix_sort_words(&upper, &scratch, 32, 64);
    PageVector<uint64_t> stable = words;
    std::stable_sort(stable.begin(), stable.end(),
                     [](uint64_t a, uint64_t b) { return (a >> 32) < (b >> 32); });
    EXPECT_EQ(upper, stable);
    for (const int threads : {2, 3, 5}) {  // parts scatter at once, still stably
      PageVector<uint64_t> parted = words;
      radix_sort_words(&parted, &scratch, 32, 64, threads);
      EXPECT_EQ(parted, stable) << threads;
    }
  }
}

TEST(Bricks, OrderIsMortonOrderOfEveryFiniteParticle) {
  // 300 k: large enough for the two-thread key pass; non-finite particles in both halves.
  constexpr uint32_t kN = 300000;
  std::vector<double> xyz = random_points(kN, 3);
  xyz[3 * 17 + 1] = std::nan("");  // left out
  xyz[3 * 250001] = INFINITY;
  const ParticleArrays p = borrow(xyz);
  BrickOptions opt;
  opt.level_layout = false;  // plain z-order, to compare with std::sort
  const BrickSet set = build_bricks(p, opt);
  EXPECT_EQ(set.nonfinite, 2);
  ASSERT_EQ(set.particle_count(), kN - 2);
  const MortonQuantiser q = MortonQuantiser::for_bounds(set.lo, set.hi);
  std::vector<std::pair<uint64_t, uint32_t>> expect;
  for (uint32_t i = 0; i < kN; ++i)
    if (i != 17 && i != 250001) expect.emplace_back(q.key(p.position(i)), i);
  std::sort(expect.begin(), expect.end());
  for (size_t k = 0; k < expect.size(); ++k) ASSERT_EQ(set.order[k], expect[k].second) << k;
}

TEST(Bricks, BoundedCountsCoverEveryParticleAndBoundsContainThem) {
  const std::vector<double> xyz = random_points(100000, 4);
  std::vector<float> radius(100000);
  for (size_t i = 0; i < radius.size(); ++i) radius[i] = 0.01f + 0.001f * float(i % 50);
  const ParticleArrays p = borrow(xyz, &radius);
  BrickOptions opt;
  opt.max_particles = 1000;
  const BrickSet set = build_bricks(p, opt);
  std::vector<int> seen(100000, 0);
  uint32_t next = 0;
  for (const Brick &b : set.bricks) {
    EXPECT_EQ(b.first, next);
    EXPECT_GE(b.count, 1u);
    EXPECT_LE(b.count, 1000u);
    next += b.count;
    for (uint32_t k = 0; k < b.count; ++k) {
      const uint32_t i = set.order[b.first + k];
      ++seen[i];
      const glm::dvec3 x = p.position(i);
      const double r = p.radius(i);
      for (int c = 0; c < 3; ++c) {
        EXPECT_LE(b.lo[c] - b.max_radius, x[c] - r);
        EXPECT_GE(b.hi[c] + b.max_radius, x[c] + r);
      }
    }
  }
  EXPECT_EQ(next, 100000u);
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int s) { return s == 1; }));
  // Octree cells: uniform points give compact bricks, far smaller than the whole box.
  double mean_side = 0.0;
  for (const Brick &b : set.bricks)
    mean_side += std::max({b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z});
  EXPECT_LT(mean_side / set.bricks.size(), 0.35 * 8.0);
}

TEST(Bricks, RefitKeepsTheOrderAndGivesExactBoundsForMovedParticles) {
  std::vector<double> xyz = random_points(50000, 9);
  const BrickSet built = build_bricks(borrow(xyz), BrickOptions{});
  // Every particle moves a little (a few per cent of a brick's size).
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  for (double &v : xyz) v += jitter(rng);
  const ParticleArrays moved = borrow(xyz);
  BrickSet refit = built;
  ASSERT_TRUE(refit_bricks(moved, 1.25, &refit));
  EXPECT_EQ(refit.order, built.order);
  ASSERT_EQ(refit.bricks.size(), built.bricks.size());
  for (const Brick &b : refit.bricks) {
    glm::dvec3 lo(1e300), hi(-1e300);
    for (uint32_t k = 0; k < b.count; ++k) {
      lo = glm::min(lo, moved.position(refit.order[b.first + k]));
      hi = glm::max(hi, moved.position(refit.order[b.first + k]));
    }
    EXPECT_EQ(b.lo, lo);  // exact: the same min/max over the same particles
    EXPECT_EQ(b.hi, hi);
  }
  EXPECT_GT(refit.spread(), built.spread());
}

// Every index below `count` exactly once, and each brick's bounds exactly those of its particles.
void expect_valid_bricks(const BrickSet &set, const ParticleArrays &p) {
  std::vector<int> seen(size_t(p.count()), 0);
  uint32_t next = 0;
  for (const Brick &b : set.bricks) {
    EXPECT_EQ(b.first, next);
    next += b.count;
    glm::dvec3 lo(1e300), hi(-1e300);
    for (uint32_t k = 0; k < b.count; ++k) {
      const uint32_t i = set.order[b.first + k];
      ASSERT_LT(int64_t(i), p.count());
      ++seen[i];
      lo = glm::min(lo, p.position(i));
      hi = glm::max(hi, p.position(i));
    }
    EXPECT_EQ(b.lo, lo);
    EXPECT_EQ(b.hi, hi);
  }
  EXPECT_EQ(int64_t(next), p.count());
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int s) { return s == 1; }));
}

TEST(Bricks, RefitRefusesReorderedOrNonFiniteParticles) {
  std::vector<double> xyz = random_points(20000, 5);
  const BrickSet built = build_bricks(borrow(xyz), BrickOptions{});
  {  // the host sorted its atoms differently: nearly every particle left its brick
    std::vector<std::array<double, 3>> pts(xyz.size() / 3);
    std::memcpy(pts.data(), xyz.data(), xyz.size() * sizeof(double));
    std::shuffle(pts.begin(), pts.end(), std::mt19937(1));
    std::vector<double> shuffled(xyz.size());
    std::memcpy(shuffled.data(), pts.data(), xyz.size() * sizeof(double));
    BrickSet set = built;
    EXPECT_FALSE(refit_bricks(borrow(shuffled), 1.25, &set));
  }
  {
    std::vector<double> bad = xyz;
    bad[300] = std::numeric_limits<double>::quiet_NaN();
    BrickSet set = built;
    EXPECT_FALSE(refit_bricks(borrow(bad), 1.25, &set));
  }
}

TEST(Bricks, RefitRepairsWrappedAndMigratedParticles) {
  // As LAMMPS does between two render steps: a few atoms wrap through a periodic boundary,
  // leaving atoms' slots are filled with the last atoms, and arrivals are appended.
  std::vector<double> xyz = random_points(30000, 8, 0.0, 10.0);
  const BrickSet built = build_bricks(borrow(xyz), BrickOptions{});
  std::vector<double> next = xyz;
  for (size_t i = 0; i < 300; ++i) next[3 * (i * 97) + 0] += 10.0 * (i % 2 ? 1 : -1);  // wrap
  for (size_t i = 0; i < 200; ++i) {  // 200 leave: the last atom moves into the hole
    const size_t hole = 3 * (i * 131 + 7), last = next.size() - 3;
    std::copy(next.begin() + long(last), next.end(), next.begin() + long(hole));
    next.resize(last);
  }
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  for (int i = 0; i < 250; ++i) next.insert(next.end(), {u(rng), u(rng), u(rng)});  // arrive
  const ParticleArrays moved = borrow(next);
  BrickSet set = built;
  ASSERT_TRUE(refit_bricks(moved, 1.25, &set));
  expect_valid_bricks(set, moved);
  EXPECT_GT(set.bricks.size(), built.bricks.size());  // the strays got bricks of their own
  // Only wraps, same count: the strays' bricks are re-sorted, the others keep their slices.
  std::vector<double> wrapped = xyz;
  for (size_t i = 0; i < 100; ++i) wrapped[3 * (i * 211) + 1] += 10.0;
  BrickSet rewrapped = built;
  ASSERT_TRUE(refit_bricks(borrow(wrapped), 1.25, &rewrapped));
  expect_valid_bricks(rewrapped, borrow(wrapped));
  // Fewer particles than before and nothing strayed: only the dropped indices go.
  const std::vector<double> fewer(xyz.begin(), xyz.end() - 30);
  BrickSet shrunk = built;
  ASSERT_TRUE(refit_bricks(borrow(fewer), 1.25, &shrunk));
  expect_valid_bricks(shrunk, borrow(fewer));
}

// The strays of a periodic wrap lie on a plane, so their bricks are plates: a later step that
// moves every particle a little (more than a quarter of a plate's thickness) keeps every particle
// in its brick, the plates' too, instead of sorting the plates' particles out again at every step.
TEST(Bricks, RefitKeepsThinStrayBricksWhoseParticlesMoveALittle) {
  std::vector<double> xyz = random_points(30000, 12, 0.0, 10.0);
  const BrickSet built = build_bricks(borrow(xyz), BrickOptions{});
  ASSERT_GT(built.mean_edge_at_build, 0.5);
  // Every particle within 0.02 of the face x = 10 wraps to just below x = 0.
  std::vector<double> wrapped = xyz;
  size_t strays = 0;
  for (size_t i = 0; i < wrapped.size(); i += 3)
    if (wrapped[i] > 9.98) wrapped[i] -= 10.0, ++strays;
  ASSERT_GT(strays, 30u);
  BrickSet set = built;
  ASSERT_TRUE(refit_bricks(borrow(wrapped), 1.25, &set));
  expect_valid_bricks(set, borrow(wrapped));
  ASSERT_GT(set.bricks.size(), built.bricks.size());
  double thinnest = 1e300;
  for (size_t b = built.bricks.size(); b < set.bricks.size(); ++b)
    thinnest = std::min(thinnest, set.bricks[b].hi.x - set.bricks[b].lo.x);
  EXPECT_LT(thinnest, 0.02);  // the strays' bricks are plates
  // Every particle moves by up to 0.02 on every axis.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  std::vector<double> moved = wrapped;
  for (double &v : moved) v += jitter(rng);
  const std::vector<uint32_t> order(set.order.begin(), set.order.end());
  const uint64_t order_generation = set.order_generation;
  ASSERT_TRUE(refit_bricks(borrow(moved), 1.25, &set));
  expect_valid_bricks(set, borrow(moved));
  EXPECT_EQ(set.order_generation, order_generation);  // no particle left its brick
  EXPECT_TRUE(std::equal(order.begin(), order.end(), set.order.begin(), set.order.end()));
}

// The build's branch-free gather (8 bit-reversed positions at a time, then one by one) against
// the plain walk over the bit-reversed counter, at every size up to a few bricks and around powers
// of two; no slot past n - 1 is written.
TEST(LevelLayout, GatherIsTheWalkOverTheBitReversedCounter) {
  std::vector<uint32_t> sizes;
  for (uint32_t n = 0; n <= 2100; ++n) sizes.push_back(n);
  for (const uint32_t p : {4096u, 65536u}) sizes.insert(sizes.end(), {p - 1, p, p + 1, p + 7});
  for (const uint32_t n : sizes) {
    std::vector<uint32_t> want;
    for_each_in_level_layout(n, [&](uint32_t j) { want.push_back(j * 3 + 1); });
    std::vector<uint32_t> got(size_t(n) + 1, 0xdeadbeefu);
    gather_in_level_layout(
        n, [](uint32_t j) { return j * 3 + 1; }, got.data());
    ASSERT_EQ(got.back(), 0xdeadbeefu) << n;
    got.pop_back();
    ASSERT_EQ(got, want) << n;
  }
}

TEST(LevelLayout, MatchesFigure3OfRizzi2015) {
  // Eight particles in z-order 0..7: L0 = {0}, L1 = {4}, L2 = {2, 6}, L3 = {1, 5, 3, 7}.
  std::vector<uint32_t> items{0, 1, 2, 3, 4, 5, 6, 7}, scratch;
  apply_level_layout(items.data(), 8, &scratch);
  EXPECT_EQ(items, (std::vector<uint32_t>{0, 4, 2, 6, 1, 5, 3, 7}));
  // Not a power of two: still a permutation.
  std::vector<uint32_t> odd(1000);
  for (uint32_t i = 0; i < 1000; ++i) odd[i] = i;
  apply_level_layout(odd.data(), 1000, &scratch);
  std::vector<uint32_t> sorted = odd;
  std::sort(sorted.begin(), sorted.end());
  for (uint32_t i = 0; i < 1000; ++i) EXPECT_EQ(sorted[i], i);
  EXPECT_EQ(level_layout_source(0, 1000), 0u);
  EXPECT_EQ(level_layout_source(1, 1000), 512u);
}

TEST(LevelLayout, EveryBrickPrefixIsSpatiallyUniform) {
  // A dense cube: each brick's prefix should split over the brick's octants in proportion.
  std::vector<double> xyz;
  const int n = 64;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) xyz.insert(xyz.end(), {double(x), double(y), double(z)});
  const ParticleArrays p = borrow(xyz);
  const BrickSet set = build_bricks(p, BrickOptions{});
  for (const Brick &b : set.bricks) {
    const glm::dvec3 mid = 0.5 * (b.lo + b.hi);
    for (const double share : {1.0 / 8, 1.0 / 4, 0.3, 1.0 / 2}) {
      const auto m = uint32_t(share * b.count);
      int octant[8] = {0};
      for (uint32_t k = 0; k < m; ++k) {
        const glm::dvec3 x = p.position(set.order[b.first + k]);
        ++octant[(x.x > mid.x) | (x.y > mid.y) << 1 | (x.z > mid.z) << 2];
      }
      for (int o = 0; o < 8; ++o)
        EXPECT_NEAR(octant[o], m / 8.0, 0.05 * m + 1) << "share " << share << " octant " << o;
    }
  }
}

}  // namespace
}  // namespace lantern
