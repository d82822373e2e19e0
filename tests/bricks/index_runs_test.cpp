// The packed index runs (IndexRuns, 8 bytes a run): what goes in comes out, at the limits of
// every field (the largest brick numbers, offsets up to the last index below 2^32), runs are cut
// at every block boundary, and runs_of_owners' runs are the maximal runs of at most two bricks
// (within a block) that describe the owners exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include <sys/mman.h>
#include <unistd.h>

#include "core/bricks/brick_set.h"
#include "core/bricks/index_runs.h"
#include "core/particles/position_tap.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

constexpr uint32_t kBlock = IndexRuns::kBlock;
constexpr uint32_t kLargest = IndexRuns::kLargestBrick;

bool bit(const PageVector<uint64_t> &bits, int64_t i) {
  return (bits[size_t(i >> 6)] >> (i & 63) & 1) != 0;
}

// Every run read back by operator[] and by visit() agrees with `expected` (the closing run last).
void expect_runs(const IndexRuns &runs, const std::vector<IndexRun> &expected) {
  ASSERT_EQ(runs.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    const IndexRun r = runs[k];
    ASSERT_EQ(r.first, expected[k].first) << "run " << k;
    ASSERT_EQ(r.brick, expected[k].brick) << "run " << k;
    ASSERT_EQ(r.other, expected[k].other) << "run " << k;
  }
  // visit() from every part start the parts of a refit could use, including mid-block ones.
  for (const size_t begin : {size_t(0), expected.size() / 3, expected.size() - 2}) {
    size_t k = begin;
    runs.visit(begin, expected.size() - 1,
               [&](int64_t first, int64_t stop, uint32_t brick, uint32_t other) {
                 ASSERT_EQ(first, int64_t(expected[k].first)) << "run " << k;
                 ASSERT_EQ(stop, int64_t(expected[k + 1].first)) << "run " << k;
                 ASSERT_EQ(brick, expected[k].brick) << "run " << k;
                 ASSERT_EQ(other, expected[k].other) << "run " << k;
                 ++k;
               });
    EXPECT_EQ(k, expected.size() - 1);
  }
}

TEST(IndexRuns, RoundTripsTheLargestBricksAndOffsets) {
  // A run at the start of every block up to 2^32 (brick numbers cycling through the largest
  // ones), then in the last block the largest offsets: a run at 2^32 - 2, closed at 2^32 - 1.
  std::vector<IndexRun> expected;
  const uint32_t blocks = uint32_t((uint64_t(1) << 32) / kBlock);
  expected.reserve(blocks + 2);
  for (uint32_t b = 0; b < blocks; ++b) {
    const uint32_t brick = kLargest - b % 7;
    const uint32_t other = b % 3 == 0 ? kNoBrick : kLargest - (b + 1) % 5 - 1;
    expected.push_back({b * kBlock, b % 11 == 5 ? kNoBrick : brick, other});
  }
  expected.push_back({~0u - 1, kLargest, 0});
  expected.push_back({~0u, kNoBrick, kNoBrick});
  IndexRuns runs;
  for (const IndexRun &r : expected) runs.push_back(r);
  expect_runs(runs, expected);
  EXPECT_EQ(runs.back().first, ~0u);
  EXPECT_EQ(runs.front().brick, kLargest);
}

TEST(IndexRuns, CutsRunsAtBlockBoundaries) {
  // One brick over three and a half blocks, then bricks 7 and 9 interleaved across a boundary.
  const int64_t n = 5 * int64_t(kBlock);
  std::vector<uint32_t> owner(static_cast<size_t>(n), 3);
  const int64_t two = 3 * kBlock + kBlock / 2;
  for (int64_t i = two; i < n; ++i) owner[size_t(i)] = i % 2 ? 7 : 9;
  PageVector<uint64_t> in_other;
  const IndexRuns runs = runs_of_owners(owner.data(), n, n, &in_other);
  const std::vector<IndexRun> expected = {
      {0, 3, kNoBrick},
      {kBlock, 3, kNoBrick},
      {2 * kBlock, 3, kNoBrick},
      {3 * kBlock, 3, 9},  // brick 3's last half block, then the first of brick 9
      {3 * kBlock + kBlock / 2 + 1, 7, 9},
      {4 * kBlock, 9, 7},  // cut at the block: the same two bricks, now 9 first
      {uint32_t(n), kNoBrick, kNoBrick}};
  expect_runs(runs, expected);
  // Which of the two bricks each index is in: the other one exactly where its bit is set.
  for (size_t k = 0; k + 1 < expected.size(); ++k)
    for (int64_t i = expected[k].first; i < int64_t(expected[k + 1].first); ++i)
      ASSERT_EQ(bit(in_other, i) ? expected[k].other : expected[k].brick, owner[size_t(i)]) << i;
}

TEST(IndexRuns, RefusesBricksAboveTheLargest) {
  std::vector<uint32_t> owner(100, kLargest);
  PageVector<uint64_t> in_other;
  IndexRuns runs = runs_of_owners(owner.data(), 100, 100, &in_other);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0].brick, kLargest);
  owner[60] = kLargest + 1;  // the other brick of the run: not storable either
  runs = runs_of_owners(owner.data(), 100, 100, &in_other);
  EXPECT_TRUE(runs.empty());
  EXPECT_TRUE(in_other.empty());
  owner.assign(100, kLargest + 1);
  EXPECT_TRUE(runs_of_owners(owner.data(), 100, 100, &in_other).empty());
}

// runs_of_owners on random owners (bricks drawn from a few, with stretches of no brick): the runs
// cover the indices in order, stay inside their blocks, give every index its owner, and are
// maximal (each ends at the last index, a block boundary, or an owner it cannot take).
TEST(IndexRuns, RunsOfRandomOwnersAreExactAndMaximal) {
  std::mt19937 rng(7);
  for (const int64_t n : {int64_t(1), int64_t(kBlock), int64_t(3 * kBlock + 17)}) {
    std::vector<uint32_t> owner(static_cast<size_t>(n));
    uint32_t current = 0;
    for (auto &o : owner) {
      if (rng() % 16 == 0) current = rng() % 9 == 0 ? kNoBrick : uint32_t(rng() % 4) + kLargest - 4;
      o = rng() % 3 == 0 && current != kNoBrick ? current + 1 : current;
    }
    PageVector<uint64_t> in_other;
    // Held counted high enough that the runs are kept however short they are.
    const IndexRuns runs = runs_of_owners(owner.data(), n, kMinMeanRun * n, &in_other);
    ASSERT_FALSE(runs.empty());
    ASSERT_EQ(runs[0].first, 0u);
    ASSERT_EQ(runs.back().first, uint32_t(n));
    ASSERT_EQ(runs.back().brick, kNoBrick);
    for (size_t k = 0; k + 1 < runs.size(); ++k) {
      const IndexRun r = runs[k];
      const int64_t stop = runs[k + 1].first;
      ASSERT_LT(r.first, stop);
      ASSERT_EQ(r.first / kBlock, (stop - 1) / kBlock) << "run " << k << " crosses a block";
      bool other_seen = false;
      for (int64_t i = r.first; i < stop; ++i) {
        const bool in = bit(in_other, i);
        ASSERT_EQ(in ? r.other : r.brick, owner[size_t(i)]) << i;
        ASSERT_TRUE(!in || r.other != kNoBrick) << i;
        other_seen |= in;
      }
      ASSERT_EQ(other_seen, r.other != kNoBrick) << "run " << k;
      if (stop == n || stop % kBlock == 0) continue;
      const uint32_t next = owner[size_t(stop)];
      const bool could_take =
          r.brick == kNoBrick
              ? next == kNoBrick
              : next != kNoBrick && (next == r.brick || next == r.other || r.other == kNoBrick);
      ASSERT_FALSE(could_take) << "run " << k << " stops short at " << stop;
    }
  }
}

// runs_of_owners' AVX2 listing (sixteen owners a comparison, two blocks at once) against its SSE2
// one, on owners of every shape: one brick's runs of 1 to 300 (across the 16-owner windows), two
// bricks alternating or interleaved at random (pair runs that end inside a window or at its
// last lane), stretches of no brick, lengths that end a block or a window mid-way, an odd and an
// even number of blocks; brick numbers and bricks' first slots; and runs too short to keep (both
// refuse). The same runs and the same in_other bits.
TEST(IndexRuns, AvxListingGivesTheSseListingsRuns) {
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2 here";
  std::mt19937 rng(13);
  const auto list = [](bool avx2, const std::vector<uint32_t> &owner, int64_t held,
                       const std::vector<Brick> *by, PageVector<uint64_t> *bits) {
    runs_avx2_enabled() = avx2;
    IndexRuns runs = runs_of_owners(owner.data(), int64_t(owner.size()), held, bits, by);
    runs_avx2_enabled() = true;
    return runs;
  };
  // Bricks 0..15 with first slots 100 b (increasing with the numbers, as the build's are).
  std::vector<Brick> bricks(16);
  for (uint32_t b = 0; b < 16; ++b) bricks[b].first = 100 * b, bricks[b].count = 100;
  int compared = 0, refused = 0;
  for (int shape = 0; shape < 4; ++shape)
    for (const int64_t n :
         {int64_t(1), int64_t(15), int64_t(16), int64_t(17), int64_t(kBlock - 1), int64_t(kBlock),
          int64_t(kBlock + 1), int64_t(3 * kBlock + 17), int64_t(4 * kBlock)}) {
      std::vector<uint32_t> owner(static_cast<size_t>(n));
      uint32_t a = 0, b = 1;
      int64_t left = 0;
      for (int64_t i = 0; i < n; ++i) {
        if (left-- <= 0) {
          left = shape == 3 ? 1 + rng() % 3 : 1 + rng() % 300;
          a = rng() % 11 == 0 ? kNoBrick : rng() % 16;
          b = rng() % 16;
        }
        uint32_t o = a;
        if (a != kNoBrick && shape == 1) o = i % 2 ? b : a;      // alternating
        if (a != kNoBrick && shape == 2) o = rng() % 2 ? b : a;  // interleaved at random
        owner[size_t(i)] = o;
      }
      for (const bool first_slots : {false, true}) {
        std::vector<uint32_t> o = owner;
        if (first_slots)
          for (uint32_t &x : o) x = x == kNoBrick ? kNoBrick : bricks[x].first;
        const std::vector<Brick> *by = first_slots ? &bricks : nullptr;
        // Held counted high enough that the runs are kept, except for shape 3 (runs of 1-3); at
        // least the slots the bricks hold where owners are first slots (the build's case).
        int64_t held = shape == 3 ? n / 4 : kMinMeanRun * n;
        if (first_slots) held = std::max<int64_t>(held, 1600);
        PageVector<uint64_t> want_bits, got_bits;
        const IndexRuns want = list(false, o, held, by, &want_bits);
        const IndexRuns got = list(true, o, held, by, &got_bits);
        ASSERT_EQ(want.size(), got.size()) << "shape " << shape << " n " << n;
        ASSERT_EQ(want_bits.size(), got_bits.size()) << "shape " << shape << " n " << n;
        for (size_t k = 0; k < want.size(); ++k) {
          const IndexRun w = want[k], g = got[k];
          ASSERT_EQ(w.first, g.first) << "shape " << shape << " n " << n << " run " << k;
          ASSERT_EQ(w.brick, g.brick) << "shape " << shape << " n " << n << " run " << k;
          ASSERT_EQ(w.other, g.other) << "shape " << shape << " n " << n << " run " << k;
        }
        for (size_t k = 0; k < want_bits.size(); ++k)
          ASSERT_EQ(want_bits[k], got_bits[k]) << "shape " << shape << " n " << n << " word " << k;
        ++compared;
        refused += want.empty();
      }
    }
  EXPECT_EQ(compared, 72);
  EXPECT_GT(refused, 0);             // the too-short shape was refused (by both)
  EXPECT_LT(refused, compared / 2);  // and the others kept
  // A two-brick run's window at every offset in a 64-bit word of in_other bits: brick 3 for s
  // owners, then 3 and 5 alternating for 80 (the other brick in every window's last lane too),
  // then brick 7: windows whose bits spill into the next word at every shift.
  for (int64_t s = 1; s <= 64; ++s) {
    std::vector<uint32_t> owner(static_cast<size_t>(s + 80 + 20), 7);
    for (int64_t i = 0; i < s; ++i) owner[size_t(i)] = 3;
    for (int64_t i = s; i < s + 80; ++i) owner[size_t(i)] = (i - s) % 2 ? 3 : 5;
    PageVector<uint64_t> want_bits, got_bits;
    const int64_t held = kMinMeanRun * int64_t(owner.size());
    const IndexRuns want = list(false, owner, held, nullptr, &want_bits);
    const IndexRuns got = list(true, owner, held, nullptr, &got_bits);
    ASSERT_EQ(want.size(), got.size()) << "s " << s;
    ASSERT_TRUE(want_bits == got_bits) << "s " << s;
  }
}

// The vector kernels of scan_runs this processor runs, one at a time: while a Kernel lives,
// scan_runs may use only its kernel (none: scan_stretch).
class Kernel {
 public:
  enum Which { kScalar, kAvx2 };
  explicit Kernel(Which k) {
#if LANTERN_SCAN_X86
    scan_kernel_enabled(ScanKernel::kAvx2) = k == kAvx2;
#endif
  }
  ~Kernel() {
#if LANTERN_SCAN_X86
    scan_kernel_enabled(ScanKernel::kAvx2) = true;
#endif
  }
  Kernel(const Kernel &) = delete;
  Kernel &operator=(const Kernel &) = delete;

  static std::vector<Which> vector_kernels() {
    std::vector<Which> k;
#if LANTERN_SCAN_X86
    if (scan_kernel_available(ScanKernel::kAvx2)) k.push_back(kAvx2);
#endif
    return k;
  }
  static const char *name(Which k) {
    return k == kAvx2 ? "AVX2" : "scalar";
  }
};

// A set over indices [0, n) whose runs are those of `owner` (kept however short), every index
// held.
BrickSet set_of_owners(const std::vector<uint32_t> &owner, uint32_t bricks) {
  const auto n = int64_t(owner.size());
  PageVector<uint64_t> in_other;
  BrickSet set;
  set.runs = runs_of_owners(owner.data(), n, kMinMeanRun * n, &in_other);
  set.in_other = std::move(in_other);
  set.bricks.resize(bricks);
  set.order.resize(size_t(n));  // particle_count(): every index held
  return set;
}

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// Every field of two scans, bit for bit (zero bounds included).
void expect_same_scans(const PageVector<BrickScan> &want, const PageVector<BrickScan> &got,
                       const char *kernel) {
  ASSERT_EQ(want.size(), got.size());
  for (size_t b = 0; b < want.size(); ++b) {
    const BrickScan &s = want[b], &v = got[b];
    EXPECT_EQ(s.finite, v.finite) << kernel << " brick " << b;
    EXPECT_EQ(s.all_published, v.all_published) << kernel << " brick " << b;
    EXPECT_TRUE(same_bits(s.r, v.r)) << kernel << " brick " << b;
    if (!s.finite) continue;
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(same_bits(s.lo[c], v.lo[c])) << kernel << " brick " << b << " " << c;
      EXPECT_TRUE(same_bits(s.hi[c], v.hi[c])) << kernel << " brick " << b << " " << c;
    }
  }
}

// scan_runs with each vector kernel the processor runs against scan_stretch, on packed xyz
// doubles owned at random by a few bricks in runs of every length (one particle up to hundreds,
// one brick or two interleaved at random, now and then none), jittered, with exact zeros of both
// signs, and with a few NaN and infinite coordinates in some of them: every brick's bounds,
// radius, finiteness and publication bit for bit (the AVX2 kernel visits each brick's particles in
// scan_stretch's order, so even its zero bounds keep the same sign).
TEST(IndexRuns, VectorScanGivesTheScalarScansBounds) {
  if (Kernel::vector_kernels().empty()) GTEST_SKIP() << "no vector kernel here";
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> coord(-3.0, 5.0);
  for (const bool non_finite : {false, true}) {
    const int64_t n = 3 * kBlock + 101;
    const uint32_t bricks = 40;
    std::vector<uint32_t> owner(static_cast<size_t>(n));
    for (int64_t i = 0; i < n;) {
      const int64_t len = std::min<int64_t>(n - i, rng() % 4 == 0 ? 1 + rng() % 3 : rng() % 300);
      const uint32_t a = uint32_t(rng() % bricks), b = uint32_t(rng() % bricks);
      const unsigned share = unsigned(rng() % 3);  // none, some, most in the second brick
      // Now and then a stretch in no brick, which the kernels skip.
      const bool held = rng() % 8 != 0;
      for (int64_t k = i; k < i + len; ++k)
        owner[size_t(k)] = !held ? kNoBrick : share != 0 && rng() % 4 < 2 * share - 1 ? b : a;
      i += len;
    }
    const BrickSet set = set_of_owners(owner, bricks);
    ASSERT_FALSE(set.runs.empty());
    std::vector<double> xyz(static_cast<size_t>(3 * n));
    for (double &v : xyz) v = coord(rng);
    // Every fourth brick's x at or above zero, and some of them exactly zero, of either sign:
    // bounds of exactly zero, whose sign depends on the order the particles are met in.
    for (int64_t i = 0; i < n; ++i)
      if (owner[size_t(i)] % 4 == 0)
        xyz[size_t(3 * i)] =
            rng() % 8 == 0 ? (rng() % 2 ? -0.0 : 0.0) : std::abs(xyz[size_t(3 * i)]);
    if (non_finite)
      for (int k = 0; k < 6; ++k)
        xyz[size_t(rng() % xyz.size())] = k % 3 == 0   ? std::nan("")
                                          : k % 3 == 1 ? INFINITY
                                                       : -INFINITY;
    const InterleavedPositions<double> pos{reinterpret_cast<const unsigned char *>(xyz.data()),
                                           int64_t(3 * sizeof(double))};
    // The last published index below n: the indices past it mark their bricks unpublished.
    const int64_t count = n - 7;
    for (const int threads : {1, 3}) {
      PageVector<BrickScan> want;
      {
        const Kernel scalar(Kernel::kScalar);
        want = scan_runs(pos, ConstantReal{0.0}, KeepAll{}, false, count, set, threads);
      }
      int non_finite_bricks = 0, zero_bricks = 0;
      for (const BrickScan &s : want)
        non_finite_bricks += !s.finite, zero_bricks += has_zero_bound(s);
      EXPECT_EQ(non_finite_bricks > 0, non_finite);
      EXPECT_GT(zero_bricks, 0);
      for (const Kernel::Which k : Kernel::vector_kernels()) {
        const Kernel only(k);
        expect_same_scans(want,
                          scan_runs(pos, ConstantReal{0.0}, KeepAll{}, false, count, set, threads),
                          Kernel::name(k));
      }
    }
  }
}

// Records the stripes a scan hands on (PositionTap), per part: the parts' threads hand theirs at
// once, each to its own list.
class StripeTap : public PositionTap {
 public:
  explicit StripeTap(const double *xyz) : xyz_(xyz) {}
  void begin(int parts) override {
    ++begun;
    stripes.assign(size_t(parts), {});
  }
  void take(int part, const double *xyz, int64_t first, int64_t end) override {
    EXPECT_EQ(xyz, xyz_);
    ASSERT_LT(size_t(part), stripes.size());
    stripes[size_t(part)].push_back({first, end});
  }
  int begun = 0;
  std::vector<std::vector<std::pair<int64_t, int64_t>>> stripes;

 private:
  const double *xyz_;
};

// A scan with a tap (the AVX2 kernel) gives the bounds of a scan without one and hands the tap
// every published particle once - also the ones published since the runs were listed (count
// beyond them); with fewer published, only those: on one thread in stripes in index order from
// 0, on several each part's stripes in order and the parts, in order, one after the other.
TEST(IndexRuns, ATappedScanGivesTheSameBoundsAndHandsOnEveryPosition) {
  if (Kernel::vector_kernels().empty()) GTEST_SKIP() << "no vector kernel here";
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> coord(-3.0, 5.0);
  const int64_t n = 50 * kBlock + 101;  // three parts on three threads (64 Ki particles each)
  const uint32_t bricks = 50;
  std::vector<uint32_t> owner(static_cast<size_t>(n));
  for (int64_t i = 0; i < n;) {
    const int64_t len = std::min<int64_t>(n - i, 1 + int64_t(rng() % 200));
    const uint32_t a = uint32_t(rng() % bricks), b = uint32_t(rng() % bricks);
    for (int64_t k = i; k < i + len; ++k) owner[size_t(k)] = rng() % 3 == 0 ? b : a;
    i += len;
  }
  const BrickSet set = set_of_owners(owner, bricks);
  ASSERT_FALSE(set.runs.empty());
  std::vector<double> xyz(static_cast<size_t>(3 * (n + 60)));
  for (double &v : xyz) v = coord(rng);
  const InterleavedPositions<double> pos{reinterpret_cast<const unsigned char *>(xyz.data()),
                                         int64_t(3 * sizeof(double))};
  for (const int64_t count : {n, n - 7, n + 60}) {
    for (const int threads : {1, 2, 3}) {
      const PageVector<BrickScan> want =
          scan_runs(pos, ConstantReal{0.0}, KeepAll{}, false, count, set, threads);
      StripeTap tap(xyz.data());
      expect_same_scans(
          want, scan_runs(pos, ConstantReal{0.0}, KeepAll{}, false, count, set, threads, &tap),
          "tapped");
      EXPECT_EQ(tap.begun, 1);
      ASSERT_EQ(tap.stripes.size(), size_t(threads)) << "parts";
      int64_t next = 0;
      for (const auto &part : tap.stripes) {
        EXPECT_FALSE(part.empty()) << count << ", " << threads << " threads";
        for (const auto &[first, end] : part) {
          EXPECT_EQ(first, next) << count << ", " << threads << " threads";
          EXPECT_LT(first, end) << count;
          next = end;
        }
      }
      EXPECT_EQ(next, count) << threads << " threads";
      EXPECT_GT(tap.ms, 0.0);
    }
  }
}

// Positions that end where the process's memory does: a page that may not be read follows the
// last coordinate, so a kernel that reads past the last particle crashes the test.
class GuardedPositions {
 public:
  explicit GuardedPositions(size_t doubles) {
    const size_t page = size_t(sysconf(_SC_PAGESIZE));
    const size_t bytes = doubles * sizeof(double);
    size_ = (bytes + page - 1) / page * page + page;
    void *m = mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) return;
    base_ = static_cast<unsigned char *>(m);
    if (mprotect(base_ + size_ - page, page, PROT_NONE) != 0) return;
    data_ = reinterpret_cast<double *>(base_ + size_ - page - bytes);
  }
  ~GuardedPositions() {
    if (base_) munmap(base_, size_);
  }
  GuardedPositions(const GuardedPositions &) = delete;
  GuardedPositions &operator=(const GuardedPositions &) = delete;
  double *data() const { return data_; }  // null if the guard could not be set up

 private:
  unsigned char *base_ = nullptr;
  size_t size_ = 0;
  double *data_ = nullptr;
};

// Each vector kernel on short runs (1 to 9 particles, two bricks interleaved at random, or one),
// starting at odd and even indices and across the words of the in_other bits, against each
// brick's bounds taken directly from the owners, bit for bit: the AVX2 kernel reads a particle with
// the next one's x, poisoned, except for the last particle, whose positions end at a page that may
// not be read.
TEST(IndexRuns, VectorScanBoundsShortRunsOfEveryParity) {
  if (Kernel::vector_kernels().empty()) GTEST_SKIP() << "no vector kernel here";
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> coord(1.0, 2.0);
  const int64_t n = 2 * kBlock + 333;
  std::vector<uint32_t> owner(static_cast<size_t>(n));
  uint32_t bricks = 0;
  for (int64_t i = 0; i < n; bricks += 2) {  // each run two new bricks: the runs are these
    const int64_t len = std::min<int64_t>(n - i, 1 + int64_t(rng() % 9));
    const bool two = rng() % 4 != 0;
    for (int64_t k = i; k < i + len; ++k) owner[size_t(k)] = bricks + (two && rng() % 2 != 0);
    i += len;
  }
  const BrickSet set = set_of_owners(owner, bricks);
  ASSERT_FALSE(set.runs.empty());
  const GuardedPositions xyz(size_t(3 * n));
  ASSERT_NE(xyz.data(), nullptr);
  for (size_t k = 0; k < size_t(3 * n); ++k) xyz.data()[k] = (k % 2 == 0 ? 1.0 : -1.0) * coord(rng);
  const InterleavedPositions<double> pos{reinterpret_cast<const unsigned char *>(xyz.data()),
                                         int64_t(3 * sizeof(double))};
  PageVector<BrickScan> expected(bricks);
  for (int64_t i = 0; i < n; ++i) {
    BrickScan &e = expected[owner[size_t(i)]];
    e.lo = glm::min(e.lo, pos.get(i)), e.hi = glm::max(e.hi, pos.get(i));
  }
  for (const Kernel::Which k : Kernel::vector_kernels()) {
    const Kernel only(k);
    expect_same_scans(expected, scan_runs(pos, ConstantReal{0.0}, KeepAll{}, false, n, set, 1),
                      Kernel::name(k));
  }
}

// A non-finite position right after a run, in no brick (the build leaves such particles out):
// the AVX2 kernel reads its x with the run's last particle, in a lane it ignores, so the run's
// bricks stay finite and bounded by their own particles.
TEST(IndexRuns, VectorScanIgnoresTheNextParticlesCoordinates) {
  if (Kernel::vector_kernels().empty()) GTEST_SKIP() << "no vector kernel here";
  const int64_t n = 40;
  std::vector<uint32_t> owner(static_cast<size_t>(n), kNoBrick);
  for (int64_t i = 0; i < 30; ++i) owner[size_t(i)] = i < 10 ? 0 : 1 + uint32_t(i % 2);
  const BrickSet set = set_of_owners(owner, 3);
  std::vector<double> xyz(static_cast<size_t>(3 * n));
  for (int64_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) xyz[size_t(3 * i + c)] = 1.0 + double(i) + 0.25 * c;
  for (const double bad : {std::nan(""), -double(INFINITY), -1e300}) {
    xyz[3 * 30] = bad;  // the x after brick 1 and 2's run: smaller than every bound
    const InterleavedPositions<double> pos{reinterpret_cast<const unsigned char *>(xyz.data()),
                                           int64_t(3 * sizeof(double))};
    PageVector<BrickScan> want;
    {
      const Kernel scalar(Kernel::kScalar);
      want = scan_runs(pos, ConstantReal{0.0}, KeepAll{}, false, n, set, 1);
    }
    ASSERT_TRUE(want[0].finite && want[1].finite && want[2].finite);
    EXPECT_EQ(want[1].lo.x, 11.0);
    for (const Kernel::Which k : Kernel::vector_kernels()) {
      const Kernel only(k);
      expect_same_scans(want, scan_runs(pos, ConstantReal{0.0}, KeepAll{}, false, n, set, 1),
                        Kernel::name(k));
    }
  }
}

}  // namespace
}  // namespace lantern
