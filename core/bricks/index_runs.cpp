#include "core/bricks/index_runs.h"

#include <algorithm>
#include <optional>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_RUNS_X86 1
#include <immintrin.h>
#else
#define LANTERN_RUNS_X86 0
#endif

#include "core/common/cpu_features.h"
#include "core/common/page_allocator.h"

namespace lantern {

namespace {

// The first index from e on (below n) whose owner is not `brick`. Four owners a comparison
// where SSE2 is there: a crystal's runs are 16-63 particles long.
int64_t skip_owner(const uint32_t *owner, int64_t e, int64_t n, uint32_t brick) {
#if defined(__SSE2__)
  const __m128i b = _mm_set1_epi32(int(brick));
  for (; e + 4 <= n; e += 4) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i *>(owner + e));
    const int same = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(v, b)));
    if (same != 0xF) return e + __builtin_ctz(unsigned(~same));
  }
#endif
  while (e < n && owner[e] == brick) ++e;
  return e;
}

// Sets the bits of indices [e, e + 4) given by the low four bits of `mask` (bit k: index e + k).
inline void set_four_bits(uint64_t *bits, int64_t e, unsigned mask) {
  const int shift = int(e & 63);
  bits[size_t(e >> 6)] |= uint64_t(mask) << shift;
  if (shift > 60) bits[size_t(e >> 6) + 1] |= uint64_t(mask) >> (64 - shift);
}

// The first index from e on (below n) owned by neither `brick` nor `other`; the indices before it
// that `other` owns get their bit in `bits`.
int64_t skip_pair(const uint32_t *owner, int64_t e, int64_t n, uint32_t brick, uint32_t other,
                  uint64_t *bits) {
#if defined(__SSE2__)
  const __m128i a = _mm_set1_epi32(int(brick)), b = _mm_set1_epi32(int(other));
  for (; e + 4 <= n; e += 4) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i *>(owner + e));
    const __m128i is_other = _mm_cmpeq_epi32(v, b);
    const int either =
        _mm_movemask_ps(_mm_castsi128_ps(_mm_or_si128(_mm_cmpeq_epi32(v, a), is_other)));
    if (either != 0xF) break;  // the scalar loop finds where
    const auto mask = unsigned(_mm_movemask_ps(_mm_castsi128_ps(is_other)));
    if (mask) set_four_bits(bits, e, mask);
  }
#endif
  for (; e < n; ++e) {
    const uint32_t o = owner[e];
    if (o == brick) continue;
    if (o != other) break;
    bits[size_t(e >> 6)] |= uint64_t(1) << (e & 63);
  }
  return e;
}

// Where the run that starts at i ends: as long as the particles belong to its brick or to one
// other (the first other one met), or to no brick for a run of none. Its other brick goes to
// *other and the in_other bits of the other's particles into `bits`.
int64_t run_end(const uint32_t *owner, int64_t n, int64_t i, uint32_t *other, uint64_t *bits) {
  const uint32_t brick = owner[i];
  *other = kNoBrick;
  const int64_t e = skip_owner(owner, i + 1, n, brick);
  if (brick == kNoBrick || e == n || owner[e] == kNoBrick) return e;
  *other = owner[e];
  return skip_pair(owner, e, n, brick, *other, bits);
}

#if LANTERN_RUNS_X86
// run_end sixteen owners a comparison (two AVX2 compares), the same runs and bits, and two blocks
// of indices listed at once. Why: four owners a comparison is bound by mispredicted branches
// wherever the runs are not a lattice's regular ones (a loop exit, then a scalar tail where two
// bricks interleave). Sixteen at once find most runs' ends in one comparison each, without a
// branch per owner; that makes each run a chain of dependent loads and compares (where a run ends
// says where the next starts), which the owners asked for ahead keep in L1 and a second block's
// chain, interleaved, overlaps. lantern-bench-runs (owners of real builds, both listings in one
// process, medians of 9; tests/bench/culling/results/runs_listing_avx2.txt): a crystal in
// LAMMPS-like bins 0.67-0.68x the SSE2 listing's time at 4.9 M particles and 0.80-0.82x at 19 M;
// in lattice order, whose runs the branches predicted, 1.06-1.10x at 4.9 M and 0.82-0.91x at
// 19 M (two runs). In situ (the 1 M-atom LJ melt, an image every 100 steps) the refits' bricks
// took 8.1 instead of 9.4 ms a frame by the median, the builds' 10.6 instead of 11.7.
namespace runs_avx2 {

// The 16 owners from e (e + 16 <= the owners' end), as two vectors of eight.
struct Sixteen {
  __m256i lo, hi;
};
__attribute__((target("avx2"))) inline Sixteen load16(const uint32_t *owner, int64_t e) {
  return {_mm256_loadu_si256(reinterpret_cast<const __m256i *>(owner + e)),
          _mm256_loadu_si256(reinterpret_cast<const __m256i *>(owner + e + 8))};
}

// Bit k set where owner k of `s` is v.
__attribute__((target("avx2"))) inline unsigned equal16(const Sixteen &s, __m256i v) {
  return unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(s.lo, v)))) |
         unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(s.hi, v)))) << 8;
}

// Sets the bits of indices [e, e + 16) given by the low 16 bits of `mask` (bit k: index e + k).
inline void set_sixteen_bits(uint64_t *bits, int64_t e, unsigned mask) {
  if (mask == 0) return;
  const int shift = int(e & 63);
  bits[size_t(e >> 6)] |= uint64_t(mask) << shift;
  if (shift > 48) bits[size_t(e >> 6) + 1] |= uint64_t(mask) >> (64 - shift);
}

// run_end's result. The block's last few owners go one at a time, in this function: a call into
// the SSE2 helpers would run legacy-encoded vector code with the upper halves of the vector
// registers this code set still dirty.
__attribute__((target("avx2"))) inline int64_t run_end(const uint32_t *owner, int64_t n, int64_t i,
                                                       uint32_t *other, uint64_t *bits) {
  // 1 KiB ahead: the next runs' owners in L1 by the time the chain reaches them (without, each
  // run waited on a load from L2 or beyond: three times slower in lattice order).
  _mm_prefetch(reinterpret_cast<const char *>(owner + i + 256), _MM_HINT_T0);
  const uint32_t brick = owner[i];
  *other = kNoBrick;
  const __m256i b = _mm256_set1_epi32(int(brick));
  int64_t e = i + 1;
  for (;; e += 16) {
    if (e + 16 > n) {
      while (e < n && owner[e] == brick) ++e;
      break;
    }
    const unsigned same = equal16(load16(owner, e), b);
    if (same != 0xFFFFu) {
      e += __builtin_ctz(~same);
      break;
    }
  }
  if (brick == kNoBrick || e == n || owner[e] == kNoBrick) return e;
  *other = owner[e];
  const __m256i o = _mm256_set1_epi32(int(*other));
  for (; e + 16 <= n; e += 16) {
    const Sixteen s = load16(owner, e);  // once for both compares
    const unsigned is_other = equal16(s, o);
    const unsigned either = is_other | equal16(s, b);
    if (either != 0xFFFFu) {
      const int stop = __builtin_ctz(~either);
      set_sixteen_bits(bits, e, is_other & ((1u << stop) - 1u));
      return e + stop;
    }
    set_sixteen_bits(bits, e, is_other);
  }
  for (; e < n; ++e) {
    const uint32_t k = owner[e];
    if (k == brick) continue;
    if (k != *other) break;
    bits[size_t(e >> 6)] |= uint64_t(1) << (e & 63);
  }
  return e;
}

// A run listed ahead of its turn: its first index (its brick is that index's owner) and its other.
struct Pending {
  uint32_t first, other;
};

// The runs of two consecutive blocks, [i, ie) and [ie, je), their chains interleaved: the first
// block's handed to take(first, other) in order, the second's stored in `later` (room for a
// block's runs), their count in *count. False as soon as take() returns false.
template <typename Take>
__attribute__((target("avx2"))) bool two_blocks(const uint32_t *owner, int64_t i, int64_t ie,
                                                int64_t je, uint64_t *bits, const Take &take,
                                                Pending *later, size_t *count) {
  int64_t j = ie;
  size_t k = 0;
  uint32_t a_other, b_other;
  while (i < ie && j < je) {
    const int64_t a_end = run_end(owner, ie, i, &a_other, bits);
    const int64_t b_end = run_end(owner, je, j, &b_other, bits);
    if (!take(i, a_other)) return false;
    later[k++] = {uint32_t(j), b_other};
    i = a_end, j = b_end;
  }
  for (; i < ie;) {
    const int64_t a_end = run_end(owner, ie, i, &a_other, bits);
    if (!take(i, a_other)) return false;
    i = a_end;
  }
  for (; j < je; ++k) {
    const int64_t b_end = run_end(owner, je, j, &b_other, bits);
    later[k] = {uint32_t(j), b_other};
    j = b_end;
  }
  *count = k;
  return true;
}

}  // namespace runs_avx2
#endif

// The brick numbers of owners that are the bricks' first slots. The bricks' first slots increase
// with their numbers; a table of the first brick at or after every 2^shift-th slot leaves a few
// entries to step over (a binary search over the bricks with a cache of recent answers cost a
// tenth of the build at 100 M particles, where a gas's runs visit its bricks in random order).
// The step is the mean brick's size rounded down to a power of two, so that a look-up steps over
// about one brick: with a fixed 1024 slots, a rank's 19 M fcc particles in bricks of 145 stepped
// over seven, and listing the runs took 50 ms instead of 32 (5 M in bricks of 307: 5.0 -> 4.0 ms;
// medians of 7 and 11 alternated in one process). The table costs 4 bytes per 2^shift slots,
// about one per brick, while the runs are listed.
class BrickNumbers {
 public:
  BrickNumbers(const std::vector<Brick> &bricks, int64_t slots)
      : shift_(shift_for(slots, bricks.size())), first_(bricks.size() + 1) {
    for (size_t b = 0; b < bricks.size(); ++b) first_[b] = bricks[b].first;
    first_[bricks.size()] = ~0u;  // a sentinel past every slot
    at_.resize(size_t(slots >> shift_) + 1);
    uint32_t b = 0;
    for (size_t k = 0; k < at_.size(); ++k) {
      while (first_[b] < (uint64_t(k) << shift_)) ++b;
      at_[k] = b;
    }
  }
  uint32_t operator()(uint32_t owner) const {
    if (owner == kNoBrick) return kNoBrick;
    uint32_t n = at_[owner >> shift_];
    while (first_[n] < owner) ++n;
    return n;
  }

 private:
  // log2 of the mean brick's slots, rounded down; at least 4 (a quarter of a byte per slot even
  // where bricks are cut very small).
  static int shift_for(int64_t slots, size_t bricks) {
    const int64_t mean = bricks == 0 ? 1 : std::max<int64_t>(1, slots / int64_t(bricks));
    int shift = 4;
    while ((int64_t(2) << shift) <= mean) ++shift;
    return shift;
  }
  int shift_;
  std::vector<uint32_t> first_, at_;
};

}  // namespace

std::atomic<bool> &runs_avx2_enabled() {
  static std::atomic<bool> on{true};
  return on;
}

IndexRuns runs_of_owners(const uint32_t *owner, int64_t n, int64_t held,
                         PageVector<uint64_t> *in_other, const std::vector<Brick> *numbered_by) {
  // One pass, into a vector reserved for runs of 8 on average (a crystal's are 11-16; shorter
  // ones grow it, a copy of a few bytes a particle at worst): mapped pages, so only those
  // written are faulted in. Counting the runs first cost a second pass over the owners as long
  // as the first (a tenth of the build at 10 M particles); reserving for the most runs kept
  // would map 4 bytes a particle, which a node that does not overcommit counts in full.
  const size_t most = size_t(held / kMinMeanRun) + 1;
  const auto block_end = [n](int64_t i) {
    return std::min<int64_t>(n, (i / IndexRuns::kBlock + 1) * int64_t(IndexRuns::kBlock));
  };
  const auto storable = [](uint32_t b) { return b == kNoBrick || b <= IndexRuns::kLargestBrick; };
  if (numbered_by && numbered_by->size() > size_t(IndexRuns::kLargestBrick) + 1) {
    in_other->clear();
    return {};
  }
  std::optional<BrickNumbers> numbers;
  if (numbered_by) numbers.emplace(*numbered_by, held);
  const auto number = [&](uint32_t o) { return numbers ? (*numbers)(o) : o; };
  IndexRuns runs;
  runs.reserve(size_t(n / 8) + size_t(n / IndexRuns::kBlock) + 2);
  in_other->assign(size_t((n + 63) / 64), 0);
  uint64_t *bits = in_other->data();
  size_t held_runs = 0;
  // The run from index i with other brick `other`, appended; false where the runs cannot be kept.
  const auto take = [&](int64_t i, uint32_t other) {
    if ((owner[i] != kNoBrick && ++held_runs > most) ||  // too short to pay
        (!numbered_by && (!storable(owner[i]) || !storable(other))))
      return false;
    runs.push_back({uint32_t(i), number(owner[i]), number(other)});
    return true;
  };
  const auto refuse = [in_other] {
    in_other->clear();
    return IndexRuns{};
  };
#if LANTERN_RUNS_X86
  if (cpu_has_avx2() && runs_avx2_enabled()) {
    constexpr int64_t kBlock = IndexRuns::kBlock;
    std::vector<runs_avx2::Pending> later(kBlock);
    for (int64_t s = 0; s < n; s += 2 * kBlock) {
      const int64_t ie = std::min(n, s + kBlock), je = std::min(n, s + 2 * kBlock);
      size_t count = 0;
      if (!runs_avx2::two_blocks(owner, s, ie, je, bits, take, later.data(), &count))
        return refuse();
      for (size_t k = 0; k < count; ++k)
        if (!take(later[k].first, later[k].other)) return refuse();
    }
    runs.push_back({uint32_t(n), kNoBrick, kNoBrick});
    return runs;
  }
#endif
  for (int64_t i = 0; i < n;) {
    uint32_t other;
    const int64_t e = run_end(owner, block_end(i), i, &other, bits);
    if (!take(i, other)) return refuse();
    i = e;
  }
  runs.push_back({uint32_t(n), kNoBrick, kNoBrick});
  return runs;
}

void list_runs(int64_t bound, BrickSet *set) {
  PageVector<uint32_t> owner(static_cast<size_t>(bound), kNoBrick);
  for (size_t b = 0; b < set->bricks.size(); ++b) {
    const Brick &br = set->bricks[b];
    for (uint32_t k = 0; k < br.count; ++k) {
      const uint32_t i = set->order[br.first + k];
      if (int64_t(i) < bound) owner[i] = uint32_t(b);
    }
  }
  set->runs = runs_of_owners(owner.data(), bound, set->particle_count(), &set->in_other);
}

}  // namespace lantern
