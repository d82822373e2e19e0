// The brick build: the particles sorted along the z-order curve by (key, index), cut into octree
// cells of at most max_particles, each laid out in levels and bounded.
//
// How, in few passes over memory: a first pass computes every particle's 32-bit key prefix and
// counts the particles of each of the 4096 octree cells of level 4 (its top 12 bits); a second
// pass scatters the particle indices straight into those cells' slots of the permutation, in
// index order. Everything after that happens one top cell at a time, in cache: making the cell's
// (prefix, index) words from its indices and their prefixes, sorting them, breaking ties by the
// full key, the octree split below it (above it, the split reads the cells' counts) and the level
// layout, written back over the cell's slots. The top cells are independent, so threads take
// contiguous runs of them. Each particle's brick is noted on the way, in the keys' array; the
// runs of consecutive indices it yields let the bounds come from one streaming pass over the
// positions (index_runs.h). Scattering 4-byte indices rather than 8-byte words halves that pass's
// writes and leaves no second per-particle array to allocate (page faults cost about as much as
// the writes here).
#include "core/bricks/brick_set.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>

#include <glm/common.hpp>

#include "core/bricks/brick_steps.h"
#include "core/bricks/index_runs.h"
#include "core/bricks/morton.h"
#include "core/common/ms_since.h"
#include "core/common/page_allocator.h"
#include "core/common/rank_threads.h"
#include "core/common/uninitialized_buffer.h"
#include "core/particles/global_extent.h"
#include "core/particles/typed_access.h"

namespace lantern {

using namespace brick_steps;

namespace {

using Clock = std::chrono::steady_clock;

// The octree levels the scatter pass resolves: 8^4 = 4096 top cells (a 16 KiB count table per
// thread; at 10-100 M particles a cell holds a few thousand, sorted in cache).
constexpr int kTopLevels = 4;
constexpr int kTopShift = 32 - 3 * kTopLevels;  // a prefix's top cell is prefix >> kTopShift
constexpr size_t kTopCells = size_t(1) << (3 * kTopLevels);
using CellCounts = std::vector<uint32_t>;

// Bounds, finite and non-finite counts of the kept centres in [begin, end) (particles outside the
// group are in neither count: no brick ever holds them).
struct RangeBounds {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()};
  glm::dvec3 hi{-std::numeric_limits<double>::infinity()};
  int64_t finite = 0;
  int64_t nonfinite = 0;
};

template <typename Positions, typename Keep>
RangeBounds find_bounds(const Positions &pos, const Keep &keep, int64_t begin, int64_t end) {
  RangeBounds r;
  for (int64_t i = begin; i < end; ++i) {
    if (!keep.get(i)) continue;
    const glm::dvec3 p = pos.get(i);
    if (!finite(p)) {
      ++r.nonfinite;
      continue;
    }
    ++r.finite;
    r.lo = glm::min(r.lo, p);
    r.hi = glm::max(r.hi, p);
  }
  return r;
}

// The bounds of all kept particles, in parts merged in part order: min and max keep the first of
// equal values, so the result is the one-thread result bit for bit (even for -0 and +0).
template <typename Positions, typename Keep>
RangeBounds bounds_in_parts(const Positions &pos, const Keep &keep, int64_t n, int threads) {
  const int parts = parts_for(threads, n, kParticlesPerThread);
  std::vector<RangeBounds> part(static_cast<size_t>(parts));
  run_in_parts(parts, n, [&](int p, int64_t b, int64_t e) {
    part[size_t(p)] = find_bounds(pos, keep, b, e);
  });
  RangeBounds all = part[0];
  for (size_t p = 1; p < part.size(); ++p) {
    all.lo = glm::min(all.lo, part[p].lo);
    all.hi = glm::max(all.hi, part[p].hi);
    all.finite += part[p].finite;
    all.nonfinite += part[p].nonfinite;
  }
  return all;
}

// Which particles get a brick: every one (no bit set) unless some are outside the group or not
// finite; then a bit per particle, set for those left out.
struct LeftOut {
  PageVector<uint64_t> bits;  // empty: none left out
  bool test(int64_t i) const { return !bits.empty() && (bits[size_t(i >> 6)] >> (i & 63) & 1); }
};

// Pass 1 over particles [64 block_begin, 64 block_end): key prefixes into keys[i], the top cells'
// counts into *counts, left-out particles marked (blocks of 64 so parts share no mask word).
// *negative_zero: whether a coordinate of a held particle may be -0 (bound_bricks).
template <typename Positions, typename Keep>
void key_pass(const Positions &pos, const Keep &keep, const MortonQuantiser &q, int64_t n,
              int64_t block_begin, int64_t block_end, uint32_t *keys, LeftOut *left_out,
              CellCounts *counts, bool *negative_zero) {
  counts->assign(kTopCells, 0);
  uint32_t *c = counts->data();
  const int64_t begin = 64 * block_begin, end = std::min(n, 64 * block_end);
  if (left_out->bits.empty()) {  // every particle kept and finite: no test in the loop
    // Four count tables, one per lane of four: consecutive particles mostly fall in the same top
    // cell, and one table chained every increment on the one before (a store and a reload).
    std::vector<uint32_t> lanes(3 * kTopCells, 0);
    uint32_t *c1 = lanes.data(), *c2 = c1 + kTopCells, *c3 = c2 + kTopCells;
    uint64_t zero_sign = 0;  // set when some coordinate is -0: zero with its sign bit
    const auto minus_zero = [](double v) {
      uint64_t b;
      std::memcpy(&b, &v, sizeof b);
      return uint64_t(b == (uint64_t(1) << 63));
    };
    int64_t i = begin;
    if constexpr (std::is_same_v<Positions, InterleavedPositions<double>>) {
      // Packed doubles: their prefixes a chunk at a time (packed_prefixes), then the chunk's
      // keys counted while they are in L1.
      if (pos.stride == int64_t(3 * sizeof(double)) &&
          reinterpret_cast<uintptr_t>(pos.base) % alignof(double) == 0) {
        const auto *xyz = reinterpret_cast<const double *>(pos.base);
        constexpr int64_t kChunk = 2048;
        for (; i < end; i += kChunk) {
          const int64_t m = std::min(kChunk, end - i);
          uint32_t *key = keys + i;
          zero_sign |= uint64_t(packed_prefixes(q, xyz + 3 * i, m, key));
          int64_t k = 0;
          for (; k + 4 <= m; k += 4) {
            ++c[key[k] >> kTopShift], ++c1[key[k + 1] >> kTopShift];
            ++c2[key[k + 2] >> kTopShift], ++c3[key[k + 3] >> kTopShift];
          }
          for (; k < m; ++k) ++c[key[k] >> kTopShift];
        }
      }
    }
    for (; i + 4 <= end; i += 4) {  // four at a time (MortonQuantiser::prefix4)
      double x[4], y[4], z[4];
      for (int k = 0; k < 4; ++k) {
        const glm::dvec3 p = pos.get(i + k);
        x[k] = p.x, y[k] = p.y, z[k] = p.z;
        zero_sign |= minus_zero(p.x) | minus_zero(p.y) | minus_zero(p.z);
      }
      uint32_t *key = keys + i;
      q.prefix4(x, y, z, key);
      ++c[key[0] >> kTopShift], ++c1[key[1] >> kTopShift];
      ++c2[key[2] >> kTopShift], ++c3[key[3] >> kTopShift];
    }
    for (; i < end; ++i) {
      const glm::dvec3 p = pos.get(i);
      zero_sign |= minus_zero(p.x) | minus_zero(p.y) | minus_zero(p.z);
      const uint32_t k = q.prefix(p);
      keys[i] = k;
      ++c[k >> kTopShift];
    }
    for (size_t cell = 0; cell < kTopCells; ++cell) c[cell] += c1[cell] + c2[cell] + c3[cell];
    *negative_zero = zero_sign != 0;
    return;
  }
  *negative_zero = true;  // not looked for here: every zero bound is checked
  for (int64_t i = begin; i < end; ++i) {
    const glm::dvec3 p = pos.get(i);
    if (!keep.get(i) || !finite(p)) {
      left_out->bits[size_t(i >> 6)] |= uint64_t(1) << (i & 63);
      continue;
    }
    const uint32_t k = q.prefix(p);
    keys[i] = k;
    ++c[k >> kTopShift];
  }
}

// Pass 2: the indices of particles [begin, end) to their top cells' slots of *order, from `at`
// (this part's first slot in each cell) on; in index order, so every cell lists its particles by
// index. Indices only (4 bytes, not the 8 of a (prefix, index) word): the cell stage reads each
// prefix back from `keys` while the cell is in cache, and the permutation needs no second array.
void scatter_pass(const uint32_t *keys, const LeftOut &left_out, int64_t begin, int64_t end,
                  CellCounts at, uint32_t *order) {
  uint32_t *slot = at.data();
  if (left_out.bits.empty()) {
    // By runs of particles in one cell (a row of a crystal): its slot in a register meanwhile,
    // where slot after slot chained each particle on a store and a reload of the same counter.
    for (int64_t i = begin; i < end;) {
      const uint32_t cell = keys[i] >> kTopShift;
      uint32_t o = slot[cell];
      do order[o++] = uint32_t(i++);
      while (i < end && keys[i] >> kTopShift == cell);
      slot[cell] = o;
    }
    return;
  }
  for (int64_t i = begin; i < end; ++i)
    if (!left_out.test(i)) order[slot[keys[i] >> kTopShift]++] = uint32_t(i);
}

// After the scatter, the keys are spent and their array becomes the owners' (index_runs.h): each
// kept particle's brick, written brick by brick. Left-out particles are in no brick.
void clear_left_out_owners(const LeftOut &left_out, int64_t begin, int64_t end, uint32_t *owner) {
  if (left_out.bits.empty()) return;
  for (int64_t i = begin; i < end; ++i)
    if (left_out.test(i)) owner[i] = kNoBrick;
}

// A run of top cells handled as one: either one brick already (a cell above level 4 with at most
// max_particles, covering top cells [cell_begin, cell_end)), or one top cell to split further.
struct Unit {
  uint32_t a, b;                  // its words
  uint32_t cell_begin, cell_end;  // its top cells
  bool one_brick;
};

// The octree split above level kTopLevels, read from the top cells' first slots `start`
// (kTopCells + 1 entries): the same cells split_cells would cut, since a cell's words are exactly
// its top cells' words.
void plan_units(const std::vector<uint32_t> &start, int level, uint32_t cell, uint32_t max,
                std::vector<Unit> *out) {
  const int below = 3 * (kTopLevels - level);  // top-cell bits below this cell's
  const uint32_t c0 = cell << below, c1 = (cell + 1) << below;
  const uint32_t a = start[c0], b = start[c1];
  if (b - a <= max || level == kTopLevels) {
    out->push_back({a, b, c0, c1, b - a <= max});
    return;
  }
  for (uint32_t child = 0; child < 8; ++child) {
    const uint32_t k = cell * 8 + child;
    const int child_below = below - 3;
    if (start[(k + 1) << child_below] > start[k << child_below])
      plan_units(start, level + 1, k, max, out);
  }
}

// The digit counts of radix_sort_top_cell<kDigits>: kDigits digits of the kTopShift prefix bits
// below a top cell's, each counted over the cell's words.
template <int kDigits>
struct DigitCounts {
  static constexpr int kDigit = (kTopShift + kDigits - 1) / kDigits;
  static constexpr size_t kBuckets = size_t(1) << kDigit;
  std::array<std::array<uint32_t, kBuckets>, kDigits> count;

  void clear() {
    for (auto &c : count) c.fill(0);
  }
  void add(uint32_t prefix) {
    for (int d = 0; d < kDigits; ++d) ++count[size_t(d)][(prefix >> (d * kDigit)) & (kBuckets - 1)];
  }
};

// Sorts words w[0, n) of one top cell - all share its top prefix bits and are in index order - by
// value, i.e. by (prefix, index): an LSD radix sort on the kTopShift prefix bits below the top
// cell's, in cache, from the digits' counts *c (their words counted once, as they were made),
// skipping a digit every word shares (stable passes over words in index order: the same order
// whatever the digits).
template <int kDigits>
void radix_sort_top_cell(uint64_t *w, size_t n, DigitCounts<kDigits> *c,
                         UninitializedBuffer<uint64_t> *scratch) {
  constexpr int kDigit = DigitCounts<kDigits>::kDigit;
  constexpr size_t kBuckets = DigitCounts<kDigits>::kBuckets;
  scratch->resize(std::max(scratch->size(), n));
  auto &count = c->count;
  // A digit every word shares reorders nothing (checked before the sums replace the counts).
  bool sort[kDigits];
  for (int d = 0; d < kDigits; ++d)
    sort[d] = count[size_t(d)][(w[0] >> (32 + d * kDigit)) & (kBuckets - 1)] != n;
  uint32_t sum[kDigits] = {};  // every digit's exclusive sums in one walk over the buckets
  for (size_t b = 0; b < kBuckets; ++b)
    for (int d = 0; d < kDigits; ++d) {
      const uint32_t k = count[size_t(d)][b];
      count[size_t(d)][b] = sum[d];
      sum[d] += k;
    }
  uint64_t *src = w, *dst = scratch->data();
  for (int d = 0; d < kDigits; ++d) {
    if (!sort[d]) continue;
    const int shift = 32 + d * kDigit;
    std::array<uint32_t, kBuckets> &cd = count[size_t(d)];
    for (size_t i = 0; i < n; ++i) dst[cd[(src[i] >> shift) & (kBuckets - 1)]++] = src[i];
    std::swap(src, dst);
  }
  if (src != w) std::copy(src, src + n, w);
}

// Top cells of fewer words than this sort by three 7-bit digits, larger ones by two 10-bit
// digits. Why: a digit's buckets are zeroed and summed whatever the cell's size, and 2 x 1024 of
// them cost more than a third pass over a cell of a few hundred words, as in situ ranks build
// (the 1 M-atom LJ melt's ranks sort 2048 top cells of about 244 words). Per word 7.5 against
// 4.4 ns at 128 words, 4.4 against 4.2 at 512, 3.7 against 3.9 at 768 (a throwaway timing of both
// sorts on the same random words, the same order checked); the LJ ranks' cell stage 4.6-4.8 ->
// 4.1-4.2 ms a build (tests/bench/culling/results/build_sort_seven_bit_digits.txt). At 19 M
// particles a rank (about 4600 words a cell) three digits sorted the top cells in 70 ms against
// 53.
constexpr size_t kSevenBitCellsBelow = 640;

// Scratch of one thread's top-cell sorts.
struct TopCellSorter {
  UninitializedBuffer<uint64_t> scratch;
  DigitCounts<3> seven_bit;
  DigitCounts<2> ten_bit;
};

// w[k] = word(k) for k < n, the n words of one top cell, then sorted: std::sort for a few words,
// else the radix sort with the digits that pay, its digits counted as the words are made: making
// a word waits on memory (its prefix, read at the index the scatter left), so the counting is
// nearly free there, where a read of its own cost one more pass over the cell's words.
template <typename Word>
void gather_and_sort_top_cell(const Word &word, uint32_t n, uint64_t *w, TopCellSorter *sorter) {
  static_assert(kTopShift == 20,
                "three 7-bit or two 10-bit digits cover the bits below a top cell");
  const auto gather_counted = [&](auto *counts) {
    counts->clear();
    for (uint32_t k = 0; k < n; ++k) {
      const uint64_t x = word(k);
      w[k] = x;
      counts->add(uint32_t(x >> 32));
    }
    radix_sort_top_cell(w, n, counts, &sorter->scratch);
  };
  if (n < 64) {
    for (uint32_t k = 0; k < n; ++k) w[k] = word(k);
    std::sort(w, w + n);
  } else if (n < kSevenBitCellsBelow) {
    gather_counted(&sorter->seven_bit);
  } else {
    gather_counted(&sorter->ten_bit);
  }
}

// One thread's share of the units, one at a time in cache: the unit's (prefix, index) words made
// from the indices the scatter left in *order and the prefixes in `keys`, sorted, split into
// bricks (appended to *bricks in curve order) and laid out back into *order; each particle's
// owner (its entry of `keys`, spent once read) set to its brick's first slot, a number every
// thread knows.
template <typename Positions>
void build_units(const Positions &pos, const MortonQuantiser &q, const std::vector<uint32_t> &start,
                 const Unit *units, size_t count, const BrickOptions &options, uint32_t *order,
                 uint32_t *keys, std::vector<Brick> *bricks) {
  UninitializedBuffer<uint64_t> words;
  TopCellSorter sorter;
  std::vector<std::pair<uint64_t, uint64_t>> run;
  const uint32_t max = std::max<uint32_t>(1, options.max_particles);
  for (size_t u = 0; u < count; ++u) {
    const Unit &unit = units[u];
    const uint32_t n = unit.b - unit.a;
    if (words.size() < n) words.resize(n);
    uint64_t *w = words.data();
    // The prefixes are read in index order but with gaps (a cell's particles are rows of the
    // host's arrays): asked for a hundred particles ahead, a few rows of a crystal. 32 ahead
    // left the cell stage 3 ms slower on 5 M fcc particles (36.5 against 33.4 ms, medians of ten
    // builds alternated in one process; 512 ahead: 33.3).
    const uint32_t *idx = order + unit.a;
    constexpr uint32_t kAhead = 128;
    for (uint32_t c = unit.cell_begin; c < unit.cell_end; ++c) {
      const uint32_t a = start[c] - unit.a;
      const auto word = [&](uint32_t k) {
        k += a;
        if (k + kAhead < n) __builtin_prefetch(keys + idx[k + kAhead]);
        const uint32_t i = idx[k];
        return uint64_t(keys[i]) << 32 | i;
      };
      gather_and_sort_top_cell(word, start[c + 1] - start[c], w + a, &sorter);
    }
    break_ties(pos, q, w, 0, n, &run);
    const size_t first_new = bricks->size();
    if (unit.one_brick) {
      Brick br;
      br.count = n;
      bricks->push_back(br);
    } else {
      split_cells(w, 0, n, kTopLevels, max, bricks);
    }
    for (size_t k = first_new; k < bricks->size(); ++k) {
      Brick &br = (*bricks)[k];
      lay_out_brick(w, br, options.level_layout, order + unit.a);
      br.first += unit.a;
      const uint32_t *idx = order + br.first;
      for (uint32_t j = 0; j < br.count; ++j) keys[idx[j]] = br.first;
    }
  }
}

// Every brick's bounds and largest radius: streaming the positions through set->runs where the
// set has them, else brick by brick. negative_zero: whether a held coordinate may be -0.
template <typename Positions, typename Radii>
void bound_bricks(const Positions &pos, const Radii &radius, int threads, bool negative_zero,
                  BrickSet *set) {
  const auto by_brick = [&](size_t b) {
    Brick &br = set->bricks[b];
    bound_brick(pos, radius, set->has_radius, set->order.data() + br.first, br.count, &br);
  };
  if (set->runs.empty()) {
    const int parts = parts_for(threads, set->particle_count(), kParticlesPerThread);
    run_in_parts(parts, int64_t(set->bricks.size()), [&](int, int64_t b, int64_t e) {
      for (int64_t k = b; k < e; ++k) by_brick(size_t(k));
    });
    return;
  }
  const PageVector<BrickScan> scans = scan_runs(pos, radius, KeepAll{}, set->has_radius,
                                                std::numeric_limits<int64_t>::max(), *set, threads);
  for (size_t b = 0; b < scans.size(); ++b) {
    // A bound of zero is -0 or +0 as the brick's own order decides, as it always did - unless no
    // held coordinate is -0: then every zero is +0 and the order changes no bit.
    if (negative_zero && has_zero_bound(scans[b])) {
      by_brick(b);
      continue;
    }
    Brick &br = set->bricks[b];
    br.lo = scans[b].lo, br.hi = scans[b].hi, br.max_radius = scans[b].r;
  }
}

}  // namespace

namespace brick_steps {

// Described in brick_steps.h (refit_bricks cuts its strays' words with it too).
void split_cells(const uint64_t *words, uint32_t a, uint32_t b, int level, uint32_t max,
                 std::vector<Brick> *out) {
  if (b - a <= max || level >= kMaxSplitLevel) {
    for (uint32_t s = a; s < b; s += max) {  // a crowded finest cell: cut it linearly
      Brick br;
      br.first = s;
      br.count = std::min(max, b - s);
      out->push_back(br);
    }
    return;
  }
  const int shift = 32 - 3 * (level + 1);
  const auto digit = [&](uint64_t w) { return (word_prefix(w) >> shift) & 7u; };
  uint32_t start = a;
  for (uint32_t child = 0; child < 8 && start < b; ++child) {
    const uint64_t *end = std::partition_point(words + start, words + b,
                                               [&](uint64_t w) { return digit(w) <= child; });
    const auto stop = uint32_t(end - words);
    if (stop > start) split_cells(words, start, stop, level + 1, max, out);
    start = stop;
  }
}

}  // namespace brick_steps

BrickSet build_bricks(const ParticleArrays &particles, const BrickOptions &options,
                      BrickBuildTimings *timings) {
  BrickBuildTimings t;
  BrickSet set;
  const int64_t n = particles.count();
  const int threads = std::max(1, options.threads);
  set.has_radius = particles.has_radius();
  auto t0 = Clock::now();
  UninitializedBuffer<uint32_t> keys;  // each particle's key prefix, then its brick (its owner)
  std::vector<uint32_t> start(kTopCells + 1, 0);  // each top cell's first slot
  MortonQuantiser q;
  bool negative_zero = true;  // whether a held particle may have a coordinate of -0
  visit_positions(particles, [&](const auto &pos) {
    visit_kept(particles, [&](const auto &keep) {
      int64_t finite_count = 0;
      if (const Extent *e = options.known_extent) {
        set.lo = {e->lo[0], e->lo[1], e->lo[2]};
        set.hi = {e->hi[0], e->hi[1], e->hi[2]};
        set.nonfinite = e->nonfinite_count;
        finite_count = e->finite_count;
      } else {
        const RangeBounds all = bounds_in_parts(pos, keep, n, threads);
        set.lo = all.lo, set.hi = all.hi, set.nonfinite = all.nonfinite;
        finite_count = all.finite;
      }
      t.bounds_ms = ms_since(t0);
      t0 = Clock::now();
      q = MortonQuantiser::for_bounds(set.lo, set.hi);
      // Pass 1: key prefixes and the top cells' counts.
      keys.resize(static_cast<size_t>(n));
      ask_huge_pages(keys.data(), keys.size() * sizeof(uint32_t));
      LeftOut left_out;
      if (finite_count < n) left_out.bits.assign(size_t((n + 63) / 64), 0);
      const int64_t blocks = (n + 63) / 64;
      const int parts = parts_for(threads, n, kParticlesPerThread);
      std::vector<CellCounts> counts(static_cast<size_t>(parts));
      std::vector<char> minus_zero(static_cast<size_t>(parts), 0);
      run_in_parts(parts, blocks, [&](int p, int64_t b, int64_t e) {
        bool z = true;
        key_pass(pos, keep, q, n, b, e, keys.data(), &left_out, &counts[size_t(p)], &z);
        minus_zero[size_t(p)] = z;
      });
      negative_zero = std::find(minus_zero.begin(), minus_zero.end(), 1) != minus_zero.end();
      t.keys_ms = ms_since(t0);
      t0 = Clock::now();
      // Pass 2: each part scatters from its own slots, after the earlier parts' particles of the
      // same cell: the cells list their particles in index order whatever the thread count.
      uint32_t sum = 0;
      for (size_t c = 0; c < kTopCells; ++c) {
        start[c] = sum;
        for (int p = 0; p < parts; ++p) {
          const uint32_t k = counts[size_t(p)][c];
          counts[size_t(p)][c] = sum;
          sum += k;
        }
      }
      start[kTopCells] = sum;
      set.order.reserve(sum);  // mapped, not yet written: huge pages before resize() zeroes it
      ask_huge_pages(set.order.data(), size_t(sum) * sizeof(uint32_t));
      set.order.resize(sum);
      run_in_parts(parts, blocks, [&](int p, int64_t b, int64_t e) {
        scatter_pass(keys.data(), left_out, 64 * b, std::min(n, 64 * e), counts[size_t(p)],
                     set.order.data());
        clear_left_out_owners(left_out, 64 * b, std::min(n, 64 * e), keys.data());
      });
      t.scatter_ms = ms_since(t0);
    });
  });
  t0 = Clock::now();
  if (!set.order.empty()) {
    std::vector<Unit> units;
    plan_units(start, 0, 0, std::max<uint32_t>(1, options.max_particles), &units);
    // Threads take contiguous runs of units of about equal particle counts.
    const auto held = int64_t(set.order.size());
    const int parts = parts_for(threads, held, kParticlesPerThread);
    std::vector<std::vector<Brick>> part(static_cast<size_t>(parts));
    visit_positions(particles, [&](const auto &pos) {
      run_in_parts(parts, held, [&](int p, int64_t b, int64_t e) {
        const auto first = [&](int64_t at) {
          return size_t(std::lower_bound(units.begin(), units.end(), at,
                                         [](const Unit &u, int64_t x) { return u.a < x; }) -
                        units.begin());
        };
        const size_t u0 = p == 0 ? 0 : first(b), u1 = p + 1 == parts ? units.size() : first(e);
        build_units(pos, q, start, units.data() + u0, u1 - u0, options, set.order.data(),
                    keys.data(), &part[size_t(p)]);
      });
    });
    size_t total = 0;
    for (const std::vector<Brick> &b : part) total += b.size();
    set.bricks.reserve(total);
    for (std::vector<Brick> &b : part) {
      set.bricks.insert(set.bricks.end(), b.begin(), b.end());
      std::vector<Brick>().swap(b);
    }
    // The owners are the bricks' first slots: runs in index order, then brick numbers.
    set.runs = runs_of_owners(keys.data(), n, set.particle_count(), &set.in_other, &set.bricks);
  }
  UninitializedBuffer<uint32_t>().swap(keys);
  t.cells_ms = ms_since(t0);
  t0 = Clock::now();
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, true, 0.0, [&](const auto &radius) {
      bound_bricks(pos, radius, threads, negative_zero, &set);
    });
  });
  t.bounds_ms += ms_since(t0);
  set.spread_at_build = set.spread();
  set.spread_now = set.spread_at_build;
  if (!set.bricks.empty())
    set.mean_edge_at_build = set.spread_at_build / (3.0 * double(set.bricks.size()));
  set.generation = next_brick_generation();
  set.order_generation = set.generation;
  if (timings) *timings = t;
  return set;
}

uint64_t next_brick_generation() {
  static std::atomic<uint64_t> last{0};
  return ++last;
}

}  // namespace lantern
