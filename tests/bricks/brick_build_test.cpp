// The brick build against a plain reference: every particle's full z-order key sorted with
// std::sort, the octree split done top-down on the sorted keys, the level layout and the bounds
// computed brick by brick. The build must give the same BrickSet bit for bit - order, bricks,
// bounds - at every thread count, with and without the caller's extent, on uniform, clustered
// (many equal key prefixes, crowded finest cells) and masked or non-finite particles. The refit
// must also be the same at every thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <glm/common.hpp>

#include "core/bricks/brick_cache.h"
#include "core/bricks/brick_set.h"
#include "core/bricks/brick_steps.h"
#include "core/bricks/index_runs.h"
#include "core/bricks/level_layout.h"
#include "core/bricks/morton.h"
#include "core/particles/particle_scan.h"
#include "core/particles/typed_access.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

struct Cloud {
  std::vector<double> xyz;
  std::vector<float> radius;  // empty: none
  std::vector<int32_t> mask;  // empty: none
  ParticleArrays arrays() const {
    ParticleDescription p{};
    p.count = int64_t(xyz.size() / 3);
    p.position = {xyz.data(), DataType::kFloat64, 0};
    if (!radius.empty()) p.radius = {radius.data(), DataType::kFloat32, 0};
    if (!mask.empty()) {
      p.mask = {mask.data(), DataType::kInt32, 0};
      p.mask_bits = 2;
    }
    ParticleArrays a;
    EXPECT_OK(ParticleArrays::validate(p, &a));
    return a;
  }
};

// The reference split: a cell of at most `max` particles (or at depth 10) is a brick, cut
// linearly when crowded; else its eight children in key order.
void reference_split(const std::vector<uint64_t> &keys, uint32_t a, uint32_t b, int level,
                     uint32_t max, std::vector<Brick> *out) {
  if (b - a <= max || level >= 10) {
    for (uint32_t s = a; s < b; s += max) {
      Brick br;
      br.first = s;
      br.count = std::min(max, b - s);
      out->push_back(br);
    }
    return;
  }
  const int shift = 63 - 3 * (level + 1);  // the child digit of a 63-bit key
  uint32_t s = a;
  while (s < b) {
    uint32_t e = s;
    while (e < b && (keys[e] >> shift) == (keys[s] >> shift)) ++e;
    reference_split(keys, s, e, level + 1, max, out);
    s = e;
  }
}

BrickSet reference_build(const ParticleArrays &p, const BrickOptions &options) {
  BrickSet set;
  set.has_radius = p.has_radius();
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  std::vector<uint32_t> kept;
  for (int64_t i = 0; i < p.count(); ++i) {
    if (!p.kept(i)) continue;
    const glm::dvec3 x = p.position(i);
    if (!(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z))) {
      ++set.nonfinite;
      continue;
    }
    lo = glm::min(lo, x), hi = glm::max(hi, x);
    kept.push_back(uint32_t(i));
  }
  set.lo = lo, set.hi = hi;
  const MortonQuantiser q = MortonQuantiser::for_bounds(lo, hi);
  std::vector<std::pair<uint64_t, uint32_t>> sorted;
  for (const uint32_t i : kept) sorted.emplace_back(q.key(p.position(i)), i);
  std::sort(sorted.begin(), sorted.end());
  std::vector<uint64_t> keys;
  for (const auto &s : sorted) keys.push_back(s.first), set.order.push_back(s.second);
  // The split reads only the key bits above the sort word's 32 (levels of 3 bits from the top).
  std::vector<uint64_t> prefix_keys;
  for (const uint64_t k : keys) prefix_keys.push_back(k >> 31 << 31);
  if (!keys.empty())
    reference_split(prefix_keys, 0, uint32_t(keys.size()), 0, options.max_particles, &set.bricks);
  std::vector<uint32_t> scratch;
  for (Brick &b : set.bricks) {
    if (options.level_layout) apply_level_layout(set.order.data() + b.first, b.count, &scratch);
    glm::dvec3 blo(INFINITY), bhi(-INFINITY);
    double r = 0.0;
    for (uint32_t k = 0; k < b.count; ++k) {
      const uint32_t i = set.order[b.first + k];
      blo = glm::min(blo, p.position(i)), bhi = glm::max(bhi, p.position(i));
      if (set.has_radius) r = std::max(r, p.radius(i));
    }
    b.lo = blo, b.hi = bhi, b.max_radius = r;
  }
  return set;
}

// Bit for bit: -0 and +0 compare equal but are different bounds.
bool same_bits(const glm::dvec3 &a, const glm::dvec3 &b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

void expect_same(const BrickSet &got, const BrickSet &want, const char *what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(got.nonfinite, want.nonfinite);
  EXPECT_TRUE(same_bits(got.lo, want.lo));
  EXPECT_TRUE(same_bits(got.hi, want.hi));
  ASSERT_EQ(got.order.size(), want.order.size());
  EXPECT_TRUE(got.order == want.order);
  ASSERT_EQ(got.bricks.size(), want.bricks.size());
  for (size_t k = 0; k < want.bricks.size(); ++k) {
    const Brick &a = got.bricks[k], &b = want.bricks[k];
    ASSERT_EQ(a.first, b.first) << "brick " << k;
    ASSERT_EQ(a.count, b.count) << "brick " << k;
    ASSERT_TRUE(same_bits(a.lo, b.lo)) << "brick " << k;
    ASSERT_TRUE(same_bits(a.hi, b.hi)) << "brick " << k;
    ASSERT_EQ(a.max_radius, b.max_radius) << "brick " << k;
  }
}

// Builds at 1, 2, 3 and 5 threads, with and without the scanned extent, and compares each with
// the reference.
void check_against_reference(const Cloud &c, BrickOptions options = {}) {
  const ParticleArrays p = c.arrays();
  const BrickSet want = reference_build(p, options);
  const Extent scanned = scan_particles(p, p.has_radius(), 0.0);
  for (const int threads : {1, 2, 3, 5}) {
    options.threads = threads;
    options.known_extent = nullptr;
    expect_same(build_bricks(p, options), want, "scanning its own bounds");
    options.known_extent = &scanned;
    expect_same(build_bricks(p, options), want, "the caller's extent");
  }
}

std::vector<double> uniform(size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-3.0, 5.0);
  std::vector<double> xyz(3 * n);
  for (double &v : xyz) v = u(rng);
  return xyz;
}

TEST(BrickBuild, MatchesTheReferenceOnUniformPoints) {
  Cloud c;
  c.xyz = uniform(400000, 11);
  check_against_reference(c);
  BrickOptions plain;
  plain.level_layout = false;
  plain.max_particles = 300;
  check_against_reference(c, plain);
}

TEST(BrickBuild, MatchesTheReferenceOnClusteredPointsWithEqualKeys) {
  // A dense blob far from a sparse halo: a few top cells hold most particles, thousands share a
  // key prefix (ties broken by the full key) and whole runs share the full key (a crowded finest
  // cell, cut linearly; ties by index).
  Cloud c;
  std::mt19937_64 rng(12);
  std::normal_distribution<double> g(0.0, 1e-4);
  std::uniform_real_distribution<double> u(-100.0, 100.0);
  for (int i = 0; i < 250000; ++i) {
    if (i % 5 == 0)
      c.xyz.insert(c.xyz.end(), {u(rng), u(rng), u(rng)});
    else if (i % 5 == 1)
      c.xyz.insert(c.xyz.end(), {1.0, 2.0, 3.0});  // exactly equal positions
    else
      c.xyz.insert(c.xyz.end(), {1.0 + g(rng), 2.0 + g(rng), 3.0 + g(rng)});
  }
  c.radius.resize(c.xyz.size() / 3);
  for (size_t i = 0; i < c.radius.size(); ++i) c.radius[i] = 0.1f + 0.01f * float(i % 7);
  check_against_reference(c);
}

TEST(BrickBuild, MatchesTheReferenceWithAGroupAndNonFinitePositions) {
  Cloud c;
  c.xyz = uniform(300000, 13);
  c.xyz[3 * 17 + 1] = std::nan("");
  c.xyz[3 * 250001] = INFINITY;
  c.mask.resize(c.xyz.size() / 3);
  for (size_t i = 0; i < c.mask.size(); ++i) c.mask[i] = (i % 3 == 0) ? 1 : 2;  // bit 2: kept
  check_against_reference(c);
}

TEST(BrickBuild, SmallAndEmptySets) {
  for (const size_t n : {size_t(0), size_t(1), size_t(2), size_t(3), size_t(1025), size_t(5000)}) {
    Cloud c;
    c.xyz = uniform(n, unsigned(20 + n));
    check_against_reference(c);
  }
  Cloud same;  // every particle at one point: one finest cell, cut linearly
  same.xyz.assign(3 * 5000, 0.5);
  check_against_reference(same);
}

// break_ties reads and reorders words [a, b) only: here the word after b shares the last word's
// prefix and has a smaller full key, so a scan that looked past b would swap the two (as the
// scan four pairs a step once did on five words: AddressSanitizer found it reading w[b]).
TEST(BreakTies, TouchesOnlyItsRange) {
  const std::vector<double> xyz{0.1,  0.1,  0.1,  0.15, 0.15, 0.15, 0.2,        0.2, 0.2,
                                0.25, 0.25, 0.25, 0.3,  0.3,  0.3,  0.3 - 2e-6, 0.3, 0.3};
  const MortonQuantiser q = MortonQuantiser::for_bounds(glm::dvec3(0.0), glm::dvec3(1.0));
  const InterleavedPositions<double> pos{reinterpret_cast<const unsigned char *>(xyz.data()),
                                         int64_t(3 * sizeof(double))};
  std::vector<uint64_t> w;
  for (uint32_t i = 0; i < 6; ++i) w.push_back(brick_steps::make_word(q.key(pos.get(i)), i));
  ASSERT_TRUE(std::is_sorted(w.begin(), w.begin() + 5));
  ASSERT_EQ(brick_steps::word_prefix(w[4]), brick_steps::word_prefix(w[5]));
  ASSERT_LT(q.key(pos.get(5)), q.key(pos.get(4)));
  for (size_t a = 0; a < 5; ++a) {
    std::vector<uint64_t> v = w;
    std::vector<std::pair<uint64_t, uint64_t>> run;
    brick_steps::break_ties(pos, q, v.data(), a, 5, &run);
    EXPECT_EQ(v, w) << "from word " << a;
  }
}

// A simple-cubic lattice of n^3 points in lattice order (x fastest), as a simulation that keeps
// its atoms spatially sorted publishes them: bricks are runs of consecutive indices.
Cloud lattice(int n, double origin) {
  Cloud c;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        c.xyz.insert(c.xyz.end(), {origin + x, origin + y * 1.01, origin + z * 0.99});
  return c;
}

TEST(BrickBuild, StreamsBoundsThroughIndexRunsOnSortedParticles) {
  Cloud c = lattice(70, 0.5);
  const BrickSet set = build_bricks(c.arrays(), BrickOptions{});
  ASSERT_FALSE(set.runs.empty());  // lattice order: long runs, kept
  EXPECT_LE((set.runs.size() - 1) * kMinMeanRun, size_t(set.particle_count()));
  // The runs list every particle once, in index order, each in the brick that holds it.
  std::vector<uint32_t> brick_of(set.order.size());
  for (size_t b = 0; b < set.bricks.size(); ++b)
    for (uint32_t k = 0; k < set.bricks[b].count; ++k)
      brick_of[set.order[set.bricks[b].first + k]] = uint32_t(b);
  ASSERT_EQ(set.runs.front().first, 0u);
  ASSERT_EQ(set.runs.back().first, set.order.size());
  ASSERT_EQ(set.runs.back().brick, kNoBrick);
  size_t two = 0;
  for (size_t k = 0; k + 1 < set.runs.size(); ++k) {
    const IndexRun &r = set.runs[k];
    ASSERT_LT(r.first, set.runs[k + 1].first);
    ASSERT_NE(r.brick, kNoBrick);  // every particle is in a brick
    ASSERT_NE(r.brick, r.other);
    two += r.other != kNoBrick;
    for (uint32_t i = r.first; i < set.runs[k + 1].first; ++i) {
      const bool other = (set.in_other[i / 64] >> (i % 64)) & 1;
      ASSERT_TRUE(!other || r.other != kNoBrick);
      ASSERT_EQ(brick_of[i], other ? r.other : r.brick) << i;
    }
    // Maximal: the next run's first particle is in neither of this run's bricks (or starts a
    // block of IndexRuns, where every run is cut).
    const uint32_t next = set.runs[k + 1].first;
    if (next < set.order.size() && next % IndexRuns::kBlock != 0 && r.other != kNoBrick)
      ASSERT_TRUE(brick_of[next] != r.brick && brick_of[next] != r.other);
  }
  EXPECT_GT(two, 0u);  // rows that cross a brick boundary
  check_against_reference(c);
}

// Bounds of exactly zero with -0 and +0 mixed at random: which one min or max keeps depends on
// the order the particles are met in. The lattice is published back to front, so a brick's
// first particle in index order is its far corner and in the brick's own order its near one.
Cloud zero_planes(int n, unsigned seed) {
  Cloud c = lattice(n, -double(n / 2));
  for (size_t i = 0; i < c.xyz.size(); i += 3) c.xyz[i + 1] *= 1.0 / 1.01;  // y = 0 exactly too
  std::reverse(c.xyz.begin(), c.xyz.end());  // z, y, x per point, last point first
  for (size_t i = 0; i < c.xyz.size(); i += 3) std::swap(c.xyz[i], c.xyz[i + 2]);
  std::mt19937 rng(seed);
  for (double &v : c.xyz)
    if (v == 0.0) v = rng() % 2 ? -0.0 : 0.0;
  return c;
}

TEST(BrickBuild, ZeroBoundsKeepTheSignTheBricksOwnOrderGives) {
  const Cloud c = zero_planes(40, 1);
  ASSERT_FALSE(build_bricks(c.arrays(), BrickOptions{}).runs.empty());
  check_against_reference(c);
}

TEST(BrickRefit, StreamingThroughRunsGivesTheGatheredBounds) {
  Cloud c = zero_planes(70, 2);  // planes at exactly 0 inside: zero bounds on both paths
  const BrickSet built = build_bricks(c.arrays(), BrickOptions{});
  ASSERT_FALSE(built.runs.empty());
  Cloud moved = c;
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  for (size_t i = 0; i < moved.xyz.size(); ++i)
    if (moved.xyz[i] != 0.0) moved.xyz[i] += jitter(rng);
  for (double &v : moved.xyz)
    if (v == 0.0) v = rng() % 2 ? -0.0 : 0.0;
  BrickSet gathered = built;
  gathered.runs.clear();  // the brick-by-brick path
  ASSERT_TRUE(refit_bricks(moved.arrays(), 1.25, &gathered));
  for (const int threads : {1, 2, 3}) {
    BrickSet streamed = built;
    BrickOptions options;
    options.threads = threads;
    ASSERT_TRUE(refit_bricks(moved.arrays(), 1.25, &streamed, options));
    EXPECT_EQ(streamed.runs.size(), built.runs.size());  // nothing strayed: the same runs
    expect_same(streamed, gathered, "streamed");
  }
  // A stray: the slow path moves particles, and the runs are listed again for the new bricks.
  for (size_t i = 0; i < 40; ++i) moved.xyz[3 * (i * 8001)] += 30.0;
  BrickSet strayed = built;
  ASSERT_TRUE(refit_bricks(moved.arrays(), 1.25, &strayed));
  ASSERT_FALSE(strayed.runs.empty());
  std::vector<int> seen(strayed.order.size(), 0);
  for (size_t k = 0; k + 1 < strayed.runs.size(); ++k)
    for (uint32_t i = strayed.runs[k].first; i < strayed.runs[k + 1].first; ++i) {
      ++seen[i];
      const bool other = (strayed.in_other[i / 64] >> (i % 64)) & 1;
      const Brick &b = strayed.bricks[other ? strayed.runs[k].other : strayed.runs[k].brick];
      EXPECT_NE(
          std::find(strayed.order.begin() + b.first, strayed.order.begin() + b.first + b.count, i),
          strayed.order.begin() + b.first + b.count);
    }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int s) { return s == 1; }));
}

// The slow refit sorts out the bricks that lost particles by streaming their runs in index order
// (sort_out_through_runs); the bricks, their order and their bounds (signed zeros and radii
// included) must be those of sorting them out brick by brick in each brick's order (the path a set
// without runs takes), at any thread count: with strays (some from the planes at exactly 0, whose
// bricks are bounded again in their own order), indices no longer published and, with a group,
// particles that left it.
TEST(BrickRefit, SortingOutThroughRunsGivesTheGatheredBricks) {
  for (const bool group : {false, true}) {
    SCOPED_TRACE(group ? "with a group" : "without a group");
    Cloud c = zero_planes(60, 4);
    const size_t n = c.xyz.size() / 3;
    for (size_t i = 0; i < n; ++i) c.radius.push_back(0.3f + 0.1f * float(i % 4));
    if (group) c.mask.assign(n, 2);  // bit 2: kept
    const BrickSet built = build_bricks(c.arrays(), BrickOptions{});
    ASSERT_FALSE(built.runs.empty());
    Cloud moved = c;
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> jitter(-0.05, 0.05);
    for (double &v : moved.xyz) v = v == 0.0 ? (rng() % 2 ? -0.0 : 0.0) : v + jitter(rng);
    for (size_t i = 0; i < 300; ++i) moved.xyz[3 * (i * 701)] += 25.0;
    size_t from_zero = 0;
    for (size_t i = 0; i < n && from_zero < 60; i += 37)
      if (moved.xyz[3 * i] == 0.0) moved.xyz[3 * i + 1] += 25.0, ++from_zero;
    ASSERT_EQ(from_zero, 60u);
    if (group)
      for (size_t i = 0; i < 200; ++i) moved.mask[i * 997 + 5] = 1;  // left the group
    moved.xyz.resize(moved.xyz.size() - 3 * 100);  // the last 100 are no longer published
    moved.radius.resize(n - 100);
    if (group) moved.mask.resize(n - 100);
    BrickSet gathered = built;
    gathered.runs.clear();  // the brick-by-brick path
    ASSERT_TRUE(refit_bricks(moved.arrays(), 1.25, &gathered));
    EXPECT_FALSE(gathered.order == built.order);             // particles moved between bricks
    EXPECT_GT(gathered.bricks.size(), built.bricks.size());  // the strays' bricks
    for (const int threads : {1, 2, 3}) {
      BrickSet streamed = built;
      BrickOptions options;
      options.threads = threads;
      ASSERT_TRUE(refit_bricks(moved.arrays(), 1.25, &streamed, options));
      expect_same(streamed, gathered, "sorted out through the runs");
    }
  }
}

// The streaming refit against brute force: a lattice in lattice order (long runs, many of them
// shared by two bricks) published as records with a byte stride, in double and in float, with a
// radius per particle, moved a little; every brick's bounds and largest radius must be exactly
// the min and max over the brick's own particles.
template <typename T>
void check_refit_against_brute_force(unsigned seed) {
  const Cloud lat = lattice(60, 0.5);
  const int64_t n = int64_t(lat.xyz.size() / 3);
  // A record per particle: an id, the position, a pad, the radius (stride 6 * sizeof(T)).
  constexpr int kFields = 6;
  std::vector<T> rec(size_t(n * kFields), T(0));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> radius(0.1, 0.4);
  for (int64_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) rec[size_t(i * kFields + 1 + c)] = T(lat.xyz[size_t(3 * i + c)]);
  for (int64_t i = 0; i < n; ++i) rec[size_t(i * kFields + 5)] = T(radius(rng));
  const DataType type = sizeof(T) == 4 ? DataType::kFloat32 : DataType::kFloat64;
  const auto arrays = [&] {
    ParticleDescription p{};
    p.count = n;
    p.position = {rec.data() + 1, type, int64_t(kFields * sizeof(T))};
    p.radius = {rec.data() + 5, type, int64_t(kFields * sizeof(T))};
    ParticleArrays a;
    EXPECT_OK(ParticleArrays::validate(p, &a));
    return a;
  };
  const BrickSet built = build_bricks(arrays(), BrickOptions{});
  ASSERT_FALSE(built.runs.empty());
  size_t two = 0;
  for (const IndexRun &r : built.runs) two += r.other != kNoBrick;
  ASSERT_GT(two, 0u);  // the two-brick path is taken
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  for (int64_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) rec[size_t(i * kFields + 1 + c)] += T(jitter(rng));
    rec[size_t(i * kFields + 5)] = T(radius(rng));
  }
  const ParticleArrays moved = arrays();
  for (const int threads : {1, 3}) {
    BrickSet set = built;
    BrickOptions options;
    options.threads = threads;
    ASSERT_TRUE(refit_bricks(moved, 1.25, &set, options));
    ASSERT_EQ(set.runs.size(), built.runs.size());  // nothing strayed: it went through the runs
    ASSERT_TRUE(set.order == built.order);
    glm::dvec3 all_lo(INFINITY), all_hi(-INFINITY);
    for (size_t b = 0; b < set.bricks.size(); ++b) {
      const Brick &br = set.bricks[b];
      glm::dvec3 lo(INFINITY), hi(-INFINITY);
      double r = 0.0;
      for (uint32_t k = 0; k < br.count; ++k) {
        const uint32_t i = set.order[br.first + k];
        const glm::dvec3 x(rec[i * kFields + 1], rec[i * kFields + 2], rec[i * kFields + 3]);
        lo = glm::min(lo, x), hi = glm::max(hi, x);
        r = std::max(r, double(rec[i * kFields + 5]));
      }
      ASSERT_TRUE(same_bits(br.lo, lo)) << "brick " << b;
      ASSERT_TRUE(same_bits(br.hi, hi)) << "brick " << b;
      ASSERT_EQ(br.max_radius, r) << "brick " << b;
      all_lo = glm::min(all_lo, lo), all_hi = glm::max(all_hi, hi);
    }
    EXPECT_TRUE(same_bits(set.lo, all_lo));
    EXPECT_TRUE(same_bits(set.hi, all_hi));
  }
}

TEST(BrickRefit, StreamedBoundsAreTheBruteForceMinMaxOfStridedDoubles) {
  check_refit_against_brute_force<double>(21);
}

TEST(BrickRefit, StreamedBoundsAreTheBruteForceMinMaxOfStridedFloats) {
  check_refit_against_brute_force<float>(22);
}

// After a refit, the bricks' bounds stand in for the step's scan (the runtime then skips it):
// the same Extent bit for bit, or a refusal where the bricks cannot tell.
TEST(BrickRefit, BricksGiveTheScansExtent) {
  Cloud c = lattice(40, 0.25);
  c.radius.assign(c.xyz.size() / 3, 0.5f);
  for (size_t i = 0; i < c.radius.size(); i += 7) c.radius[i] = 0.75f;
  c.mask.assign(c.xyz.size() / 3, 2);
  for (size_t i = 0; i < c.mask.size(); i += 5) c.mask[i] = 1;  // outside the group
  BrickCache cache;
  double ms = 0.0;
  std::string how;
  cache.for_step(c.arrays(), 0, BrickOptions{}, &ms, &how);
  EXPECT_EQ(how, "built");
  for (double &v : c.xyz) v += 0.01;
  ASSERT_TRUE(cache.refit_first(c.arrays(), 1, BrickOptions{}));
  Extent from_bricks;
  ASSERT_TRUE(extent_of_bricks(cache.bricks(), c.arrays(), &from_bricks));
  const Extent scanned = scan_particles(c.arrays(), true, 0.0);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(from_bricks.lo[size_t(k)], scanned.lo[size_t(k)]);
    EXPECT_EQ(from_bricks.hi[size_t(k)], scanned.hi[size_t(k)]);
  }
  EXPECT_EQ(from_bricks.max_radius, 0.75);
  EXPECT_EQ(from_bricks.max_radius, scanned.max_radius);
  EXPECT_EQ(from_bricks.finite_count, scanned.finite_count);
  EXPECT_EQ(from_bricks.nonfinite_count, scanned.nonfinite_count);
  // The step's first for_step reports the refit made ahead; the next ones the cache.
  ms = 0.0;
  cache.for_step(c.arrays(), 1, BrickOptions{}, &ms, &how);
  EXPECT_EQ(how, "refit");
  cache.for_step(c.arrays(), 1, BrickOptions{}, &ms, &how);
  EXPECT_EQ(how, "cached");
  EXPECT_FALSE(cache.refit_first(c.arrays(), 1, BrickOptions{}));  // already made
  // A bound of exactly zero: -0 or +0 depends on the order particles are met in: refused.
  // The row x = 1 moves to exactly 0; it is the group's lowest (every particle of the row x = 0
  // has an index that is a multiple of 5: outside the group).
  const double x1 = c.xyz[3];
  for (size_t i = 0; i < c.xyz.size(); i += 3) c.xyz[i] -= x1;
  ASSERT_TRUE(cache.refit_first(c.arrays(), 2, BrickOptions{}));
  EXPECT_FALSE(extent_of_bricks(cache.bricks(), c.arrays(), &from_bricks));
  // A NaN in the group: a rebuild, so no refit ahead.
  c.xyz[3 * 101 + 1] = std::nan("");
  EXPECT_FALSE(cache.refit_first(c.arrays(), 3, BrickOptions{}));
  cache.for_step(c.arrays(), 3, BrickOptions{}, &ms, &how);
  EXPECT_EQ(how, "built");
}

// A host that rewrites its arrays in place under the same step number between two calls gets
// bricks for the new positions: the fingerprint one call took is never trusted in the next, nor
// by a caller that marks no calls; within a call the step's bricks are cached.
TEST(BrickCache, NoticesArraysRewrittenInPlaceBetweenCalls) {
  for (const bool marks_calls : {true, false}) {
    Cloud c = lattice(30, 0.25);
    BrickCache cache;
    double ms = 0.0;
    std::string how;
    if (marks_calls) cache.begin_call();
    cache.for_step(c.arrays(), 5, BrickOptions{}, &ms, &how);
    EXPECT_EQ(how, "built");
    cache.for_step(c.arrays(), 5, BrickOptions{}, &ms, &how);
    EXPECT_EQ(how, "cached");
    for (double &v : c.xyz) v += 0.01;  // the same step, rewritten in place
    if (marks_calls) {                  // as the runtime does: a call, its refit ahead of the scan
      cache.begin_call();
      EXPECT_TRUE(cache.refit_first(c.arrays(), 5, BrickOptions{}));
    }
    cache.for_step(c.arrays(), 5, BrickOptions{}, &ms, &how);
    EXPECT_EQ(how, "refit") << marks_calls;
    const Extent scanned = scan_particles(c.arrays(), false, 0.0);
    EXPECT_EQ(cache.bricks().lo, glm::dvec3(scanned.lo[0], scanned.lo[1], scanned.lo[2]));
    cache.for_step(c.arrays(), 5, BrickOptions{}, &ms, &how);
    EXPECT_EQ(how, "cached");
  }
}

// Particles spreading about their lattice sites, as in a liquid: the refit at step 10 tells how
// fast the bricks loosen, and at step 20 the cache builds without trying a refit, which would
// still have passed but whose growth says the next would not; one step later (11) it refits.
TEST(BrickCache, BuildsWithoutTryingARefitThatItsGrowthSaysEndsTooLoose) {
  const Cloud sites = lattice(40, 0.5);
  const auto spread_to = [&](double amplitude, unsigned seed) {
    Cloud c = sites;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-amplitude, amplitude);
    for (double &v : c.xyz) v += u(rng);
    return c;
  };
  const Cloud at10 = spread_to(0.65, 1), at20 = spread_to(0.8, 2);
  for (const int64_t later : {int64_t(20), int64_t(11)}) {
    BrickCache cache;
    double ms = 0.0;
    std::string how;
    cache.for_step(sites.arrays(), 0, BrickOptions{}, &ms, &how);
    ASSERT_EQ(how, "built");
    cache.for_step(at10.arrays(), 10, BrickOptions{}, &ms, &how);
    ASSERT_EQ(how, "refit");
    const BrickSet &refit = cache.bricks();
    const double ratio = refit.spread() / refit.spread_at_build;
    ASSERT_GT(ratio, 1.12);
    ASSERT_LT(ratio, 1.2);
    BrickSet tried = cache.bricks();
    ASSERT_TRUE(refit_bricks(at20.arrays(), 1.25, &tried));  // would still pass
    cache.for_step(at20.arrays(), later, BrickOptions{}, &ms, &how);
    EXPECT_EQ(how, later == 20 ? "built" : "refit") << later;
    EXPECT_EQ(cache.bricks().particle_count(), int64_t(sites.xyz.size() / 3));
  }
}

TEST(BrickRefit, IsTheSameAtEveryThreadCount) {
  Cloud c;
  c.xyz = uniform(300000, 14);
  const BrickSet built = build_bricks(c.arrays(), BrickOptions{});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.01, 0.01);
  Cloud moved = c;
  for (double &v : moved.xyz) v += jitter(rng);
  for (size_t i = 0; i < 500; ++i) moved.xyz[3 * (i * 541)] += 4.0;  // strays: new bricks
  BrickSet one = built;
  BrickOptions options;
  ASSERT_TRUE(refit_bricks(moved.arrays(), 1.25, &one, options));
  EXPECT_GT(one.bricks.size(), built.bricks.size());
  for (const int threads : {2, 3, 5}) {
    BrickSet many = built;
    options.threads = threads;
    ASSERT_TRUE(refit_bricks(moved.arrays(), 1.25, &many, options));
    expect_same(many, one, "refit");
  }
}

}  // namespace
}  // namespace lantern
