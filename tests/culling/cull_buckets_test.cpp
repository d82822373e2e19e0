// order_front_to_back: a brick's candidates as buckets - a permutation of them, the buckets tiling
// it in order, each bucket's box holding its spheres (what bucket_hidden's exactness rests on),
// nearest depth slab first, and buckets cut across the view as well as in depth (so that a
// slanted surface's hidden layers can be proven hidden a bucket at a time).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/culling/cull_pass.h"

namespace lantern {
namespace {

// n candidates in the view-space box [lo, hi] of centres, radius r (or random radii in [r/2, r]).
UninitializedBuffer<Candidate> cloud(int n, glm::dvec3 lo, glm::dvec3 hi, double r, bool mixed,
                                     unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  UninitializedBuffer<Candidate> out;
  for (int k = 0; k < n; ++k) {
    const glm::dvec3 c(lo.x + (hi.x - lo.x) * u(rng), lo.y + (hi.y - lo.y) * u(rng),
                       lo.z + (hi.z - lo.z) * u(rng));
    out.push_back({c, mixed ? r * (0.5 + 0.5 * u(rng)) : r, uint32_t(k), 1.0f});
  }
  return out;
}

// The invariants every call must keep.
void expect_buckets_valid(const CandidateBuffers &b) {
  const auto &in = b.gathered, &out = b.sorted;
  ASSERT_EQ(out.size(), in.size());
  std::vector<uint32_t> a, s;
  for (const Candidate &c : in) a.push_back(c.index);
  for (const Candidate &c : out) s.push_back(c.index);
  std::sort(a.begin(), a.end()), std::sort(s.begin(), s.end());
  EXPECT_EQ(a, s) << "sorted is not a permutation of gathered";
  uint32_t next = 0;
  for (const DepthBucket &d : b.buckets) {
    EXPECT_EQ(d.begin, next);
    EXPECT_LT(d.begin, d.end) << "an empty bucket";
    next = d.end;
    // The box is the bounds of its spheres, exactly (DepthBucket: bounds of c - r and c + r).
    double near = std::numeric_limits<double>::infinity();
    glm::dvec3 box_lo(std::numeric_limits<double>::infinity()), box_hi = -box_lo;
    for (uint32_t k = d.begin; k < d.end; ++k) {
      const Candidate &c = out[k];
      for (int i = 0; i < 3; ++i) {
        box_lo[i] = std::min(box_lo[i], c.c[i] - c.r);
        box_hi[i] = std::max(box_hi[i], c.c[i] + c.r);
      }
      near = std::min(near, -c.c.z - c.r);
    }
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(d.lo[i], box_lo[i]) << "axis " << i;
      EXPECT_EQ(d.hi[i], box_hi[i]) << "axis " << i;
    }
    EXPECT_EQ(d.near, near);
  }
  EXPECT_EQ(next, uint32_t(out.size()));
}

// Any count, odd ones and a single candidate too (the bounds are taken two at a time).
TEST(CullBuckets, EveryCountFromOne) {
  for (const int n : {1, 2, 3, 7, 64, 499}) {
    CandidateBuffers b;
    b.gathered =
        cloud(n, glm::dvec3(-1.0, -2.0, -12.0), glm::dvec3(1.5, 0.5, -9.0), 0.4, true, unsigned(n));
    order_front_to_back(&b);
    SCOPED_TRACE(n);
    expect_buckets_valid(b);
  }
}

TEST(CullBuckets, PermutationBoxesAndNearestSlabFirst) {
  for (const bool mixed : {false, true}) {
    CandidateBuffers b;
    const glm::dvec3 lo(-3.0, 1.0, -40.0), hi(2.0, 4.0, -30.0);
    b.gathered = cloud(500, lo, hi, 0.3, mixed, mixed ? 7u : 3u);
    order_front_to_back(&b);
    expect_buckets_valid(b);
    // Front to back to the resolution of the slabs: no candidate comes after one more than a
    // sixteenth of the depth range deeper (the order only makes occluders come early, but it
    // keeps the particles drawn those of depth order).
    const double slab = (hi.z - lo.z) / 16.0 * (1.0 + 1e-9);
    double deepest = -std::numeric_limits<double>::infinity();
    for (const DepthBucket &d : b.buckets) {
      double bucket_deepest = deepest;
      for (uint32_t k = d.begin; k < d.end; ++k) {
        EXPECT_GT(-b.sorted[k].c.z, deepest - 2.0 * slab);
        bucket_deepest = std::max(bucket_deepest, -b.sorted[k].c.z);
      }
      deepest = bucket_deepest;
    }
  }
}

TEST(CullBuckets, BucketsAreCutAcrossTheView) {
  // A slab of a crystal seen at a slant: depth grows with x, so a depth slab alone spans the
  // whole y range. Each bucket must span at most half the centres' x and y ranges.
  CandidateBuffers b;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (uint32_t k = 0; k < 400; ++k) {
    const double x = 4.0 * u(rng), y = 4.0 * u(rng), t = 0.5 * u(rng);
    b.gathered.push_back({glm::dvec3(x, y, -20.0 - x - t), 0.2, k, 1.0f});
  }
  order_front_to_back(&b);
  expect_buckets_valid(b);
  double x_lo = 1e300, x_hi = -1e300, y_lo = 1e300, y_hi = -1e300;
  for (const Candidate &c : b.gathered)
    x_lo = std::min(x_lo, c.c.x), x_hi = std::max(x_hi, c.c.x), y_lo = std::min(y_lo, c.c.y),
    y_hi = std::max(y_hi, c.c.y);
  for (const DepthBucket &d : b.buckets) {
    // The box grows each centre by the radius 0.2 on both sides.
    EXPECT_LE(d.hi.y - d.lo.y - 0.4, 0.5 * (y_hi - y_lo) * (1.0 + 1e-9));
    EXPECT_LE(d.hi.x - d.lo.x - 0.4, 0.5 * (x_hi - x_lo) * (1.0 + 1e-9));
  }
}

TEST(CullBuckets, DegenerateRangesAndEmpty) {
  CandidateBuffers b;
  order_front_to_back(&b);
  EXPECT_TRUE(b.sorted.empty());
  EXPECT_TRUE(b.buckets.empty());
  // All at one point, then all on one line of x: every range but one empty.
  for (uint32_t k = 0; k < 10; ++k)
    b.gathered.push_back({glm::dvec3(1.0, 2.0, -5.0), 0.1, k, 1.0f});
  order_front_to_back(&b);
  expect_buckets_valid(b);
  EXPECT_EQ(b.buckets.size(), 1u);
  for (uint32_t k = 0; k < 10; ++k) b.gathered[k].c.x = double(k);
  order_front_to_back(&b);
  expect_buckets_valid(b);
  EXPECT_EQ(b.buckets.size(), 2u);  // split across x only
}

TEST(CullBuckets, RangesTooNarrowForAFiniteScale) {
  // Denormal spreads (coordinates near 1e-310): 2 / width overflows. The scale was infinite, the
  // lowest candidate's cell 0 x inf = NaN, its index INT_MIN, and the tally wrote out of bounds.
  for (const double spread : {1e-310, 4.9e-324, 1e-300}) {
    CandidateBuffers b;
    for (uint32_t k = 0; k < 10; ++k)
      b.gathered.push_back(
          {glm::dvec3(spread * k, spread * (k % 3), -5.0 - spread * (k % 4)), 0.1, k, 1.0f});
    order_front_to_back(&b);
    SCOPED_TRACE(spread);
    expect_buckets_valid(b);
  }
}

}  // namespace
}  // namespace lantern
