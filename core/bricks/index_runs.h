// The bricks' particles as runs of consecutive indices, in index order: what lets a refit (and
// the build's bounds) read the simulation's positions in one streaming pass instead of brick by
// brick.
//
// Why: a brick's particles lie in a few dozen separate stretches of the host's arrays (a
// simulation that keeps its atoms spatially sorted, as LAMMPS and most MD codes do, stores a
// brick's x-rows one after another), and gathering brick after brick costs about twice a
// streaming pass. Listing those stretches in index order turns the gather into a stream. A run
// may hold two bricks, a bit per particle saying which: where a brick boundary cuts a row, the
// particles of the two bricks interleave (a crystal's basis atoms straddle it, a host's sorting
// bins do), and one-brick runs there would be a few particles long, each paying a loop's
// overhead. Where runs are short anyway (particles in random order) they cost more than they
// save, and the set keeps none (the refit then gathers).
//
// Bounds computed through runs visit a brick's particles in index order rather than in the
// brick's order; min and max give the same values either way, and where a bound is exactly zero
// (the only value with two encodings, -0 and +0) the brick is bounded again in its own order, so
// the bits are those of the brick-order pass.
//
// Thread-safety: pure functions; the streaming pass runs in parts on its own threads.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_SCAN_X86 1
#include <immintrin.h>
#else
#define LANTERN_SCAN_X86 0
#endif

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "core/bricks/brick_set.h"
#include "core/common/page_allocator.h"
#include "core/common/rank_threads.h"
#include "core/common/stream_prefetch.h"
#include "core/particles/position_tap.h"
#include "core/particles/typed_access.h"

namespace lantern {

// Runs shorter than this on average are not kept (8 bytes a run and a bit per particle: at most
// 2.1 bytes per particle). A crystal in lattice order gives about 10-40 (a row of two bricks; the
// shorter where the octree's cells leave bricks of a few hundred particles). Streaming even runs
// of 4-8 beats gathering brick by brick: at 100 M particles (lantern-bench --scale, the crystal
// beside a gas, whose bricks average 155 particles and whose runs 7.5) a refit took 6.9 passes
// over the positions without runs and 3.1 with them.
inline constexpr uint32_t kMinMeanRun = 4;

// The owner of an index that no brick holds.
inline constexpr uint32_t kNoBrick = ~0u;

// The runs of owner[0, n) (a brick number per index, kNoBrick for none) in index order, closed by a
// run of no brick at n, with their in_other bits (*in_other, a bit per index); each run as long as
// its particles belong to at most two bricks, and cut at every IndexRuns::kBlock-th index. None
// (both empty) when they would average fewer than kMinMeanRun of the `held` indices that have an
// owner, or when a brick is numbered above IndexRuns::kLargestBrick. With `numbered_by`, the
// owners are the bricks' first slots (Brick::first of `*numbered_by`, increasing with the brick
// numbers), and the runs get the bricks' numbers.
IndexRuns runs_of_owners(const uint32_t *owner, int64_t n, int64_t held,
                         PageVector<uint64_t> *in_other,
                         const std::vector<Brick> *numbered_by = nullptr);

// Whether runs_of_owners may use its AVX2 listing where the processor has AVX2 (tests turn it off
// to compare it with the SSE2 one: the same runs and bits).
std::atomic<bool> &runs_avx2_enabled();

// The runs of `set` from scratch (after a refit moved particles between bricks) into set->runs and
// set->in_other, or none when too short to pay. Needs a temporary of 4 bytes per index below
// `bound`.
void list_runs(int64_t bound, BrickSet *set);

// What the streaming pass finds for one brick. Laid out for the AVX2 kernel (scan_avx2): lo and
// hi each start a 32-byte line, so that a brick's bounds load and store as two aligned vectors of
// four doubles whose fourth lanes (r; the flags) the kernel leaves as they are.
struct alignas(32) BrickScan {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()};
  double r = 0.0;  // largest radius (0 without a radius array)
  glm::dvec3 hi{-std::numeric_limits<double>::infinity()};
  bool all_published = true;  // every index below the particle count and in the group
  bool finite = true;         // every such position finite
};
static_assert(sizeof(glm::dvec3) == 3 * sizeof(double) && offsetof(BrickScan, r) == 24 &&
                  offsetof(BrickScan, hi) == 32 && sizeof(BrickScan) == 64,
              "scan_avx2 reads a BrickScan as two vectors of four doubles");

// One run's particles [first, last) added to its brick's scan *s[0], or - where `bits` is given
// (a two-brick run) - to *s[1] for those whose in_other bit is set, for particles without a group
// (every index kept). No branch on a particle's bit: a two-brick run's particles interleave (a
// crystal's basis straddles the cut), so such a branch mispredicts; each brick's particles are
// taken from the bits instead (count trailing zeros), one brick after the other. Finiteness is
// summed (x - x is 0 for finite x, NaN otherwise, and a NaN stays in the sum) and checked once per
// run; a non-finite position marks both bricks of its run, which changes nothing downstream: any
// non-finite held position makes the refit ask for a rebuild. Min and max are written as
// glm::min/max and std::max are ((v < lo) ? v : lo, (hi < v) ? v : hi) and visit each brick's
// particles in the same order, so the bounds are the same bits.
template <typename Positions, typename Radii>
void scan_stretch(const Positions &pos, const Radii &radius, bool has_radius, const uint64_t *bits,
                  int64_t first, int64_t last, BrickScan *const s[2]) {
  const int n = bits ? 2 : 1;
  double lo[2][3], hi[2][3], r[2];
  for (int k = 0; k < n; ++k) {
    for (int c = 0; c < 3; ++c) lo[k][c] = s[k]->lo[c], hi[k][c] = s[k]->hi[c];
    r[k] = s[k]->r;
  }
  const auto lower = [](double a, double v) { return v < a ? v : a; };
  const auto upper = [](double a, double v) { return a < v ? v : a; };
  double nan_sum = 0.0;
  if (!bits) {
    double lx = lo[0][0], ly = lo[0][1], lz = lo[0][2], hx = hi[0][0], hy = hi[0][1], hz = hi[0][2];
    double rr = r[0];
    for (int64_t i = first; i < last; ++i) {
      const glm::dvec3 x = pos.get(i);
      nan_sum += (x.x - x.x) + (x.y - x.y) + (x.z - x.z);
      lx = lower(lx, x.x), ly = lower(ly, x.y), lz = lower(lz, x.z);
      hx = upper(hx, x.x), hy = upper(hy, x.y), hz = upper(hz, x.z);
      if (has_radius) rr = upper(rr, radius.get(i));
    }
    lo[0][0] = lx, lo[0][1] = ly, lo[0][2] = lz, hi[0][0] = hx, hi[0][1] = hy, hi[0][2] = hz;
    r[0] = rr;
  } else {
    // Each brick's particles apart, in index order (the order the bounds depend on), picked from
    // the bits 64 at a time: a brick's bounds stay in registers, where writing them per particle
    // to the brick the bit picks chained every particle on a store and a reload.
    for (int k = 0; k < 2; ++k) {
      double lx = lo[k][0], ly = lo[k][1], lz = lo[k][2], hx = hi[k][0], hy = hi[k][1];
      double hz = hi[k][2], rr = r[k];
      for (int64_t w = first >> 6; w <= (last - 1) >> 6; ++w) {
        const int64_t base = w * 64;
        uint64_t word = k == 0 ? ~bits[w] : bits[w];
        if (base < first) word &= ~uint64_t(0) << (first - base);
        if (base + 64 > last) word &= ~uint64_t(0) >> (base + 64 - last);
        while (word != 0) {
          const int64_t i = base + __builtin_ctzll(word);
          word &= word - 1;
          const glm::dvec3 x = pos.get(i);
          nan_sum += (x.x - x.x) + (x.y - x.y) + (x.z - x.z);
          lx = lower(lx, x.x), ly = lower(ly, x.y), lz = lower(lz, x.z);
          hx = upper(hx, x.x), hy = upper(hy, x.y), hz = upper(hz, x.z);
          if (has_radius) rr = upper(rr, radius.get(i));
        }
      }
      lo[k][0] = lx, lo[k][1] = ly, lo[k][2] = lz, hi[k][0] = hx, hi[k][1] = hy, hi[k][2] = hz;
      r[k] = rr;
    }
  }
  for (int k = 0; k < n; ++k) {
    for (int c = 0; c < 3; ++c) s[k]->lo[c] = lo[k][c], s[k]->hi[c] = hi[k][c];
    s[k]->r = r[k];
    s[k]->finite &= nan_sum == 0.0;
  }
}

#if LANTERN_SCAN_X86
// scan_runs's loop over a part's runs for positions stored as packed xyz doubles without a radius
// array and without a group, on a processor with AVX2 (scan_runs checks). It is also the kernel
// on processors with AVX-512: on an AVX-512 EPYC (19 M fcc particles, the kernels alternated in
// one process; docs/benchmarks.md, 4 December 2026) the masked AVX-512 kernel used until then
// took 1.45x its time, and this kernel rewritten with masked loads and masked min and max 1.2x.
// A particle's x, y, z and the next particle's x in one register, added to both bricks of its
// run: OR-ed first with all ones (a NaN) in the lanes of the brick it is not in, and in the fourth
// lane always; _mm256_min_pd(w, lo) is (w < lo) ? w : lo, so a NaN lane leaves the bound as it
// was, and a valid one updates it as scan_stretch's lower and upper do. Each brick's particles
// are visited in index order, as in scan_stretch: the same bounds bit for bit, signed zeros
// included. The bounds stay in the part's BrickScan entries (two aligned vectors each, their
// fourth lanes untouched), so a run costs two loads and stores per brick instead of a fold of six
// scalars. No branch per particle: a table row per in_other bit gives the lanes to poison.
// Finiteness is gathered over the whole part (x - x has no bit set for finite x, and is NaN
// otherwise, OR-ed together) and not per brick: where a position is not finite, scan_runs scans
// the part again with scan_stretch, which marks the bricks.
namespace scan_avx2 {

// kPoison[bit][k]: the lanes OR-ed into a particle whose in_other bit is `bit` before it is added
// to brick k of its run (0: the run's brick, 1: its other).
alignas(64) inline constexpr uint64_t kPoison[2][2][4] = {
    {{0, 0, 0, ~0ull}, {~0ull, ~0ull, ~0ull, ~0ull}},
    {{~0ull, ~0ull, ~0ull, ~0ull}, {0, 0, 0, ~0ull}}};

// The particles [first, last) of one run into the bounds of its brick (*a: a BrickScan) and, with
// kTwo, of its other (*b) as the in_other bits say; particles from `whole` on are loaded by
// their three lanes (the next particle's x may lie past the array).
template <bool kTwo>
__attribute__((target("avx2"))) inline void scan_run(const double *xyz, const uint64_t *bits,
                                                     int64_t first, int64_t last, int64_t whole,
                                                     double *a, double *b, __m256d *odd) {
  __m256d lo0 = _mm256_load_pd(a), hi0 = _mm256_load_pd(a + 4);
  __m256d lo1 = kTwo ? _mm256_load_pd(b) : lo0, hi1 = kTwo ? _mm256_load_pd(b + 4) : hi0;
  __m256d nan = *odd;
  const auto add = [&](int64_t i, __m256d v) __attribute__((target("avx2"))) {
    nan = _mm256_or_pd(nan, _mm256_sub_pd(v, v));
    const unsigned bit = kTwo ? unsigned(bits[i >> 6] >> (i & 63)) & 1u : 0u;
    const auto *poison = reinterpret_cast<const double *>(kPoison[bit]);
    const __m256d w0 = _mm256_or_pd(v, _mm256_load_pd(poison));
    lo0 = _mm256_min_pd(w0, lo0), hi0 = _mm256_max_pd(w0, hi0);
    if (kTwo) {
      const __m256d w1 = _mm256_or_pd(v, _mm256_load_pd(poison + 4));
      lo1 = _mm256_min_pd(w1, lo1), hi1 = _mm256_max_pd(w1, hi1);
    }
  };
  const int64_t mid = std::max(first, std::min(last, whole));
  for (int64_t i = first; i < mid; ++i) add(i, _mm256_loadu_pd(xyz + 3 * i));
  for (int64_t i = mid; i < last; ++i)
    add(i, _mm256_maskload_pd(xyz + 3 * i, _mm256_setr_epi64x(-1, -1, -1, 0)));
  _mm256_store_pd(a, lo0), _mm256_store_pd(a + 4, hi0);
  if (kTwo) _mm256_store_pd(b, lo1), _mm256_store_pd(b + 4, hi1);
  *odd = nan;
}

// The lines of positions of run [first, stop) not asked for yet (those before *asked), asked for
// ahead as every streaming pass does (core/common/stream_prefetch.h: at 5 M fcc particles the
// scan took 17.8 ms without and 10.9 ms with, beside a gas 23.4 against 14.5 ms).
__attribute__((target("avx2"))) inline void ask_ahead(const double *xyz, uint32_t first,
                                                      uint32_t stop, uintptr_t *asked) {
  const uintptr_t from = reinterpret_cast<uintptr_t>(xyz + 3 * int64_t(first)) & ~uintptr_t(63);
  const uintptr_t to = reinterpret_cast<uintptr_t>(xyz + 3 * int64_t(stop));
  uintptr_t line = std::max(*asked, from);
  for (; line < to; line += 64) ask_stream_line(line);
  *asked = line;
}

// The bounds of run k's bricks asked for into L1. Why: at 19 M fcc particles a rank has 65 k
// bricks, 4 MiB of bounds, beyond L2, and loading a run's bounds stalled as long as its
// positions had (a refit's scan, one thread, medians of 9 alternated runs: 57.6 -> 50.5 ms, a
// streaming pass 35.0; at 5 M, 14.7 -> 13.8 ms).
inline constexpr size_t kRunsAhead = 16;
__attribute__((target("avx2"))) inline void ask_bounds(const IndexRuns &runs, size_t k,
                                                       const BrickScan *acc) {
  uint32_t brick, other;
  runs.bricks_of(k, &brick, &other);
  if (brick != kNoBrick) _mm_prefetch(reinterpret_cast<const char *>(acc + brick), _MM_HINT_T0);
  if (other != kNoBrick) _mm_prefetch(reinterpret_cast<const char *>(acc + other), _MM_HINT_T0);
}

// Runs [begin, end) of set.runs (particles below `count`) into acc, a BrickScan per brick; false
// if a position may not be finite (then acc is to be scanned again).
__attribute__((target("avx2"))) inline bool scan_part(const double *xyz, const BrickSet &set,
                                                      size_t begin, size_t end, int64_t count,
                                                      BrickScan *acc) {
  const uint64_t *bits = set.in_other.data();
  // The particles whose four-lane load stays inside the positions (the runs end at the array's
  // end, or - in a refit - at the count of the particles when they were listed).
  const int64_t whole = std::min<int64_t>(count, set.runs.back().first) - 1;
  __m256d odd = _mm256_setzero_pd();
  IndexRuns::Reader reader(set.runs, begin);
  uintptr_t asked = 0;  // the positions' lines asked for so far end here
  for (size_t k = begin; k < end; ++k) {
    uint32_t first, stop, brick, other;
    reader.next(&first, &stop, &brick, &other);
    ask_ahead(xyz, first, stop, &asked);
    if (k + kRunsAhead < end) ask_bounds(set.runs, k + kRunsAhead, acc);
    if (brick == kNoBrick) continue;
    const int64_t last = std::min<int64_t>(stop, count);
    // Indices past the particle count are no longer published: their brick does not fit.
    for (int64_t i = last; i < stop; ++i)
      acc[other != kNoBrick && (bits[i >> 6] >> (i & 63) & 1) ? other : brick].all_published =
          false;
    auto *a = reinterpret_cast<double *>(&acc[brick]);
    if (other == kNoBrick)
      scan_run<false>(xyz, bits, first, last, whole, a, nullptr, &odd);
    else
      scan_run<true>(xyz, bits, first, last, whole, a, reinterpret_cast<double *>(&acc[other]),
                     &odd);
  }
  const __m256i xyz_lanes = _mm256_setr_epi64x(-1, -1, -1, 0);  // the fourth: another particle
  return _mm256_testz_si256(_mm256_castpd_si256(odd), xyz_lanes) != 0;
}

// scan_part over the runs of blocks [b0, b1) of indices, stripe by stripe of kTapBlocks blocks,
// each stripe's positions handed to `tap` as part `part` right after scan_part read them (then
// in cache), and, where `last`, the particles the runs do not list (added since) after its last;
// the same bounds as one scan_part. `ms`: the time spent in the tap, added. False as scan_part
// (the tap then has only some stripes).
inline bool scan_part_tapped(const double *xyz, const BrickSet &set, int64_t count,
                             PositionTap &tap, int part, size_t b0, size_t b1, bool last,
                             double *ms, BrickScan *acc) {
  constexpr size_t kTapBlocks = 4;  // 16 Ki particles, 384 KiB of positions: within L2
  const IndexRuns &runs = set.runs;
  const size_t blocks = runs.blocks(), stretches = runs.size() - 1;
  const int64_t listed = runs.back().first;
  const auto take = [&](int64_t first, int64_t end) {
    const auto t0 = std::chrono::steady_clock::now();
    tap.take(part, xyz, first, end);
    *ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  for (size_t b = b0; b < b1; b += kTapBlocks) {
    const size_t e = std::min(b1, b + kTapBlocks);
    if (!scan_part(xyz, set, runs.block_start(b), e < blocks ? runs.block_start(e) : stretches,
                   count, acc))
      return false;
    const int64_t first = int64_t(b) << IndexRuns::kOffsetBits;
    const int64_t end =
        std::min<int64_t>(count, e < blocks ? int64_t(e) << IndexRuns::kOffsetBits : listed);
    if (first < end) take(first, end);
  }
  if (last && listed < count) take(listed, count);
  return true;
}

}  // namespace scan_avx2

// The vector kernel above.
enum class ScanKernel { kAvx2 };

// Whether scan_runs may use `kernel` (tests turn it off to compare with scan_stretch).
inline std::atomic<bool> &scan_kernel_enabled(ScanKernel) {
  static std::atomic<bool> on{true};
  return on;
}

// Whether this processor (and its operating system) runs `kernel`.
inline bool scan_kernel_available(ScanKernel) {
  static const bool avx2 = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2");
  }();
  return avx2;
}

// Whether scan_runs uses `kernel` where the positions' layout allows it.
inline bool scan_kernel_usable(ScanKernel kernel) {
  return scan_kernel_enabled(kernel) && scan_kernel_available(kernel);
}
#endif

// One streaming pass over the positions through set.runs: each brick's bounds, radius and
// checks, for particles with index below `count` that are in the group (`keep`). In parts on up
// to `threads` threads, merged in part order (min and max keep the first of equal values, so the
// result is the one-thread result).
// `tap` (may be null): handed the positions as they are read where the pass runs the AVX2 kernel
// (scan_part_tapped); its parts then cut the runs at blocks of indices, each part handing on its
// own stripes (any cut between runs gives the same bounds).
template <typename Positions, typename Radii, typename Keep>
PageVector<BrickScan> scan_runs(const Positions &pos, const Radii &radius, const Keep &keep,
                                bool has_radius, int64_t count, const BrickSet &set, int threads,
                                PositionTap *tap = nullptr) {
  const IndexRuns &runs = set.runs;
  const int parts = parts_for(threads, set.particle_count(), int64_t(1) << 16);
  // In mapped pages (a few dozen bytes per brick): freed to the system, not left in the heap.
  std::vector<PageVector<BrickScan>> part(static_cast<size_t>(parts));
  const int64_t stretches = runs.empty() ? 0 : int64_t(runs.size()) - 1;  // the last closes
  const uint64_t *bits = set.in_other.data();
#if LANTERN_SCAN_X86
  // Packed xyz doubles without radii (and without a group): with AVX2, the poisoned-lanes
  // kernel.
  bool packed_avx2 = false;
  const double *xyz = nullptr;
  if constexpr (std::is_same_v<Positions, InterleavedPositions<double>> &&
                std::is_same_v<Keep, KeepAll>) {
    const bool layout = !has_radius && pos.stride == int64_t(3 * sizeof(double)) &&
                        reinterpret_cast<uintptr_t>(pos.base) % alignof(double) == 0;
    packed_avx2 = layout && scan_kernel_usable(ScanKernel::kAvx2);
    xyz = reinterpret_cast<const double *>(pos.base);
  }
#endif
  bool tapped = false;
#if LANTERN_SCAN_X86
  tapped = packed_avx2 && tap != nullptr && !runs.empty();
#endif
  const size_t blocks = tapped ? runs.blocks() : 0;
  std::vector<double> tap_ms(static_cast<size_t>(parts), 0.0);
  if (tapped) tap->begin(parts);
  // The stretch where block b starts (tapped parts are whole blocks).
  const auto block_stretch = [&](int64_t b) {
    return size_t(b) < blocks ? int64_t(runs.block_start(size_t(b))) : stretches;
  };
  run_in_parts(parts, tapped ? int64_t(blocks) : stretches, [&](int p, int64_t b0, int64_t b1) {
    const int64_t begin = tapped ? block_stretch(b0) : b0, end = tapped ? block_stretch(b1) : b1;
    PageVector<BrickScan> &acc = part[size_t(p)];
    // Mapped, then huge pages asked for before assign() writes it whole (64 bytes a brick, 8 MiB
    // for a rank's 19 M fcc particles): the refit took 0.91x the time in one process and 0.95x
    // in lantern-bench --scale 38 than with 4 KiB faults (4 December 2026).
    acc.reserve(set.bricks.size());
    ask_huge_pages(acc.data(), set.bricks.size() * sizeof(BrickScan));
    acc.assign(set.bricks.size(), BrickScan{});
#if LANTERN_SCAN_X86
    if (packed_avx2) {
      if (tapped ? scan_avx2::scan_part_tapped(xyz, set, count, *tap, p, size_t(b0), size_t(b1),
                                               p == parts - 1, &tap_ms[size_t(p)], acc.data())
                 : scan_avx2::scan_part(xyz, set, size_t(begin), size_t(end), count, acc.data()))
        return;
      acc.assign(set.bricks.size(), BrickScan{});  // not finite: scan_stretch marks the bricks
    }
#endif
    runs.visit(
        size_t(begin), size_t(end),
        [&](int64_t first, int64_t stop, uint32_t brick, uint32_t other) {
          if (brick == kNoBrick) return;
          const int64_t last = std::min<int64_t>(stop, count);
          const auto in_other = [bits](int64_t i) { return (bits[i >> 6] >> (i & 63) & 1) != 0; };
          // Indices past the particle count are no longer published: their brick does not fit.
          for (int64_t i = last; i < stop; ++i)
            acc[other != kNoBrick && in_other(i) ? other : brick].all_published = false;
          if constexpr (std::is_same_v<Keep, KeepAll>) {
            BrickScan *const two[2] = {&acc[brick], other == kNoBrick ? nullptr : &acc[other]};
            scan_stretch(pos, radius, has_radius, two[1] ? bits : nullptr, first, last, two);
            return;
          }
          // With a group: a branch per particle on whether it is kept.
          // The run's bricks in locals (registers), written back after the run.
          BrickScan a = acc[brick];
          const auto add = [&](BrickScan &s, int64_t i) {
            if (!keep.get(i)) {
              s.all_published = false;
              return;
            }
            const glm::dvec3 x = pos.get(i);
            // x - x is 0 for finite x and NaN otherwise: a test without branches.
            s.finite &= (x.x - x.x == 0.0) & (x.y - x.y == 0.0) & (x.z - x.z == 0.0);
            s.lo = glm::min(s.lo, x), s.hi = glm::max(s.hi, x);
            if (has_radius) s.r = std::max(s.r, radius.get(i));
          };
          if (other == kNoBrick) {
            for (int64_t i = first; i < last; ++i) add(a, i);
          } else {
            BrickScan b = acc[other];
            for (int64_t i = first; i < last; ++i) {
              if (in_other(i))
                add(b, i);
              else
                add(a, i);
            }
            acc[other] = b;
          }
          acc[brick] = a;
        });
  });
  // The parts ran at once: the tap held the pass up about as long as its slowest part's share.
  if (tapped) tap->ms += *std::max_element(tap_ms.begin(), tap_ms.end());
  PageVector<BrickScan> all = std::move(part[0]);
  for (size_t p = 1; p < part.size(); ++p)
    for (size_t b = 0; b < all.size(); ++b) {
      BrickScan &a = all[b];
      const BrickScan &l = part[p][b];
      a.lo = glm::min(a.lo, l.lo), a.hi = glm::max(a.hi, l.hi);
      a.r = std::max(a.r, l.r);
      a.all_published &= l.all_published;
      a.finite &= l.finite;
    }
  return all;
}

// True when a bound of `s` is exactly zero: -0 and +0 compare equal, so which one min or max
// kept depends on the order the particles were visited in.
inline bool has_zero_bound(const BrickScan &s) {
  return s.lo.x == 0.0 || s.lo.y == 0.0 || s.lo.z == 0.0 || s.hi.x == 0.0 || s.hi.y == 0.0 ||
         s.hi.z == 0.0;
}

}  // namespace lantern
