#include "core/render/density_kernel.h"

// No fused multiply-adds (core/render/CMakeLists.txt compiles this file with -ffp-contract=off,
// as density_splat.cpp): the vectorised placement must round as the scalar one.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

#include "core/common/cpu_features.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

namespace lantern {
namespace {

constexpr double kCutoffSigmas = 3.0;
constexpr int kTapSum = 1 << kDensityTapBits;

// The samples of one table entry, scaled to integers summing to exactly 2^16 (largest
// remainder), zero taps stripped. Returns the first tap's pixel offset from floor(c - 0.5).
int table_entry(double sigma, double phase, std::vector<uint16_t> *out) {
  const double reach = kCutoffSigmas * sigma;
  const int lo = int(std::ceil(phase - reach)), hi = int(std::floor(phase + reach));
  std::vector<double> g;
  for (int t = lo; t <= hi; ++t)
    g.push_back(std::exp(-(t - phase) * (t - phase) / (2 * sigma * sigma)));
  const double total = std::accumulate(g.begin(), g.end(), 0.0);
  std::vector<uint32_t> tap(g.size());
  std::vector<double> frac(g.size());
  int64_t given = 0;
  for (size_t i = 0; i < g.size(); ++i) {
    const double v = g[i] / total * kTapSum;
    tap[i] = uint32_t(std::floor(v));
    frac[i] = v - std::floor(v);
    given += tap[i];
  }
  std::vector<size_t> order(g.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return frac[a] > frac[b]; });
  for (int64_t r = 0; r < kTapSum - given; ++r) ++tap[order[size_t(r) % order.size()]];
  size_t first = 0, last = tap.size();
  while (first < last && tap[first] == 0) ++first;
  while (last > first && tap[last - 1] == 0) --last;
  for (size_t i = first; i < last; ++i) out->push_back(uint16_t(tap[i]));
  return lo + int(first);
}

// The unquantised truncated Gaussian beyond the table, over the pixels on the image only.
}  // namespace

DensityKernelTable::DensityKernelTable() {
  for (int k = 0; k < kDensitySigmaCount; ++k) {
    const double sigma = 0.5 * std::exp2(double(k) / kDensitySigmaSteps);
    for (int j = 0; j < kDensityPhases; ++j) {
      Entry e;
      e.offset = uint32_t(taps_.size());
      e.first = int16_t(table_entry(sigma, (j + 0.5) / kDensityPhases, &taps_));
      e.count = uint16_t(taps_.size() - e.offset);
      entries_.push_back(e);
    }
  }
  // Boundaries of 4 sigma^2 within one octave [1, 2), then the next octave's first: sigma's
  // 32 steps per octave are 16 per octave of its square.
  constexpr int kSteps = kDensitySigmaSteps / 2;
  std::vector<double> bounds;
  for (int i = 1; i <= kSteps + 1; ++i) bounds.push_back(std::exp2((i - 0.5) / kSteps));
  for (int bin = 0; bin < 1024; ++bin) {
    const double start = 1.0 + bin / 1024.0;
    const auto n = std::upper_bound(bounds.begin(), bounds.end(), start) - bounds.begin();
    below_.push_back(uint8_t(n));
    next_.push_back(bounds[size_t(n)]);
  }
  below32_.assign(below_.begin(), below_.end());
  // Where each k starts: k = 16 octave + c (c = 1 .. 16) from the c-th boundary of the octave
  // on (scaled by a power of two: exact), k 0 from minus infinity.
  starts_.push_back(-HUGE_VAL);
  for (int k = 1; k <= kDensitySigmaCount; ++k)
    starts_.push_back(std::ldexp(bounds[size_t((k - 1) % kSteps)], (k - 1) / kSteps));
}

// The scalar placement: the calls place_all() stands for, one footprint at a time.
void DensityKernelTable::place_range(const double *px, const double *py, const double *sigma2,
                                     int from, int to, int width, int height,
                                     DensityPlacements *out) const {
  constexpr double kFar = double(1 << 30);  // as DensitySplatter::deposit()
  for (int i = from; i < to; ++i) {
    const auto at = size_t(i);
    const int k = index_of_variance(sigma2[at]);
    out->k[at] = k;
    out->count_x[at] = 0;
    if (k >= kDensitySigmaCount) continue;
    if (!(std::abs(px[at]) < kFar && std::abs(py[at]) < kFar)) continue;
    int base_x = 0, base_y = 0, phase_x = 0, phase_y = 0;
    place(px[at], &base_x, &phase_x);
    place(py[at], &base_y, &phase_y);
    AxisTaps ax, ay;
    if (!taps_at(base_x, phase_x, k, width, &ax) || !taps_at(base_y, phase_y, k, height, &ay))
      continue;
    out->taps_x[at] = uint32_t(ax.taps - taps_.data());
    out->taps_y[at] = uint32_t(ay.taps - taps_.data());
    out->first_x[at] = ax.first, out->first_y[at] = ay.first;
    out->count_x[at] = ax.count, out->count_y[at] = ay.count;
  }
}

#if defined(__x86_64__) && defined(__GNUC__)
namespace {

#define LANTERN_AVX512 __attribute__((target("avx512f,avx512vl,avx512dq")))
// GCC 12 warns that the undefined pass-through its AVX-512 intrinsics start from "may be used
// uninitialized" (the intrinsics themselves, not this code).
#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

// One axis of 8 footprints: place() (floor, phase in 1/32 px) and taps_at() of entries
// `k` (int32 lanes, valid where `live`), as the scalar code, in integer lanes.
struct AxisLanes {
  __m256i offset, first, count;
};
// `row`, when not null: the 32 entries (4 vectors of 8) of the one k every lane shares (all
// live), looked up by phase with permutes instead of a gather.
LANTERN_AVX512 inline AxisLanes axis_lanes(__m512d centre, __m256i k, __mmask8 live,
                                           const void *entries, int size, const __m512i *row) {
  const __m512d u = _mm512_sub_pd(centre, _mm512_set1_pd(0.5));
  const __m512d b = _mm512_roundscale_pd(u, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  const __m256i phase = _mm256_min_epi32(
      _mm512_cvttpd_epi32(_mm512_mul_pd(_mm512_sub_pd(u, b), _mm512_set1_pd(kDensityPhases))),
      _mm256_set1_epi32(kDensityPhases - 1));
  const __m256i base = _mm512_cvttpd_epi32(b);
  const __m256i index = _mm256_add_epi32(_mm256_slli_epi32(k, 5), phase);  // k * 32 + phase
  static_assert(kDensityPhases == 32, "k * 32 is a shift by 5");
  // Entry: offset (bits 0-31), first (int16, bits 32-47), count (uint16, bits 48-63).
  __m512i e;
  if (row) {
    const __m512i j = _mm512_cvtepi32_epi64(phase);
    const __m512i low = _mm512_permutex2var_epi64(row[0], j, row[1]);
    const __m512i high = _mm512_permutex2var_epi64(row[2], j, row[3]);
    e = _mm512_mask_mov_epi64(low, _mm512_test_epi64_mask(j, _mm512_set1_epi64(16)), high);
  } else {
    e = _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), live, index, entries, 8);
  }
  const __m256i offset = _mm512_cvtepi64_epi32(e);
  const __m256i first = _mm512_cvtepi64_epi32(_mm512_srai_epi64(_mm512_slli_epi64(e, 16), 48));
  const __m256i count = _mm512_cvtepi64_epi32(_mm512_srli_epi64(e, 48));
  const __m256i lo = _mm256_add_epi32(base, first);
  const __m256i hi = _mm256_sub_epi32(_mm256_add_epi32(lo, count), _mm256_set1_epi32(1));
  const __m256i a = _mm256_max_epi32(lo, _mm256_setzero_si256());
  const __m256i z = _mm256_min_epi32(hi, _mm256_set1_epi32(size - 1));
  // Empty where hi < 0 or lo > size - 1: z - a + 1 <= 0 exactly then.
  const __m256i n = _mm256_max_epi32(_mm256_add_epi32(_mm256_sub_epi32(z, a), _mm256_set1_epi32(1)),
                                     _mm256_setzero_si256());
  return {_mm256_add_epi32(offset, _mm256_sub_epi32(a, lo)), a, n};
}

template <typename T>
LANTERN_AVX512 inline void store8(T *to, __m256i lanes) {
  _mm256_storeu_si256(reinterpret_cast<__m256i *>(to), lanes);
}

}  // namespace

// index_of_variance() of 8 lanes of x = 4 sigma^2: k = 16 octave + below[bin] + (m >= next[bin])
// for x in [1, 65536), 0 below (and for NaN), kDensitySigmaCount at or above.
LANTERN_AVX512 static inline __m256i variance_index_lanes(__m512d x, const int32_t *below,
                                                          const double *next, __m512i mantissa,
                                                          __m512i exponent_one) {
  const __mmask8 at_least_one = _mm512_cmp_pd_mask(x, _mm512_set1_pd(1.0), _CMP_GE_OQ);
  const __mmask8 below_top = _mm512_cmp_pd_mask(x, _mm512_set1_pd(65536.0), _CMP_LT_OQ);
  const __m512i bits = _mm512_castpd_si512(x);
  const __m512i octave = _mm512_sub_epi64(_mm512_srli_epi64(bits, 52), _mm512_set1_epi64(1023));
  const __m512i bin = _mm512_and_si512(_mm512_srli_epi64(bits, 42), _mm512_set1_epi64(1023));
  const __m512d m =
      _mm512_castsi512_pd(_mm512_or_si512(_mm512_and_si512(bits, mantissa), exponent_one));
  // Footprints in a row of the published order mostly share a bin (and k, below): then
  // broadcasts and permutes instead of gathers (the same values).
  __m256i below_bin;
  __m512d next_bin;
  const __m512i bin0 = _mm512_permutexvar_epi64(_mm512_setzero_si512(), bin);
  if (_mm512_cmpeq_epi64_mask(bin, bin0) == 0xff) {
    const auto b0 = size_t(_mm_cvtsi128_si64(_mm512_castsi512_si128(bin)));
    below_bin = _mm256_set1_epi32(below[b0]);
    next_bin = _mm512_set1_pd(next[b0]);
  } else {
    below_bin = _mm512_i64gather_epi32(bin, below, 4);
    next_bin = _mm512_i64gather_pd(bin, next, 8);
  }
  const __mmask8 step = _mm512_cmp_pd_mask(m, next_bin, _CMP_GE_OQ);
  const __m256i k = _mm256_add_epi32(
      _mm256_add_epi32(_mm256_slli_epi32(_mm512_cvtepi64_epi32(octave), 4), below_bin),
      _mm256_maskz_mov_epi32(step, _mm256_set1_epi32(1)));
  static_assert(kDensitySigmaSteps / 2 == 16, "16 octave is a shift by 4");
  return _mm256_maskz_mov_epi32(
      at_least_one, _mm256_mask_mov_epi32(_mm256_set1_epi32(kDensitySigmaCount), below_top, k));
}

LANTERN_AVX512 static void place_avx512(const void *entries, const int32_t *below,
                                        const double *next, const double *starts, const double *px,
                                        const double *py, const double *sigma2, int count,
                                        int width, int height, DensityPlacements *out) {
  const __m512d far = _mm512_set1_pd(double(1 << 30));
  const __m512i mantissa = _mm512_set1_epi64((int64_t(1) << 52) - 1);
  const __m512i exponent_one = _mm512_set1_epi64(int64_t(1023) << 52);
  // The last vector's k (lane 0) and the range of 4 sigma^2 that has it, [lo, hi): sigma varies
  // slowly along a published order, so most vectors lie wholly in it (NaN never does).
  int last = kDensitySigmaCount;
  __m512d lo = _mm512_set1_pd(HUGE_VAL), hi = lo;
  for (int i = 0; i + 8 <= count; i += 8) {
    const __m512d x = _mm512_mul_pd(_mm512_set1_pd(4.0), _mm512_loadu_pd(sigma2 + i));
    __m256i k;
    if ((_mm512_cmp_pd_mask(x, lo, _CMP_GE_OQ) & _mm512_cmp_pd_mask(x, hi, _CMP_LT_OQ)) == 0xff) {
      k = _mm256_set1_epi32(last);
    } else {
      k = variance_index_lanes(x, below, next, mantissa, exponent_one);
      last = _mm_cvtsi128_si32(_mm256_castsi256_si128(k));
      if (last < kDensitySigmaCount)
        lo = _mm512_set1_pd(starts[last]), hi = _mm512_set1_pd(starts[last + 1]);
      else
        lo = hi = _mm512_set1_pd(HUGE_VAL);
    }
    store8(out->k.data() + i, k);
    // The farness test (also false for NaN), then every far lane's centre at 0 so that the
    // integer conversions stay in range.
    const __m512d cx = _mm512_loadu_pd(px + i), cy = _mm512_loadu_pd(py + i);
    const __mmask8 near = _mm512_cmp_pd_mask(_mm512_abs_pd(cx), far, _CMP_LT_OQ) &
                          _mm512_cmp_pd_mask(_mm512_abs_pd(cy), far, _CMP_LT_OQ);
    const __mmask8 live = near & _mm256_cmplt_epi32_mask(k, _mm256_set1_epi32(kDensitySigmaCount));
    const __m256i kl = _mm256_maskz_mov_epi32(live, k);
    __m512i row[4];
    const __m512i *shared = nullptr;
    if (live == 0xff) {
      const __m256i k0 = _mm256_permutexvar_epi32(_mm256_setzero_si256(), kl);
      if (_mm256_cmpeq_epi32_mask(kl, k0) == 0xff) {
        const auto *e0 = static_cast<const int64_t *>(entries) +
                         size_t(_mm_cvtsi128_si32(_mm256_castsi256_si128(kl))) * kDensityPhases;
        for (int v = 0; v < 4; ++v) row[v] = _mm512_loadu_si512(e0 + 8 * v);
        shared = row;
      }
    }
    const AxisLanes ax =
        axis_lanes(_mm512_maskz_mov_pd(live, cx), kl, live, entries, width, shared);
    const AxisLanes ay =
        axis_lanes(_mm512_maskz_mov_pd(live, cy), kl, live, entries, height, shared);
    const __mmask8 on = live & _mm256_cmpgt_epi32_mask(ax.count, _mm256_setzero_si256()) &
                        _mm256_cmpgt_epi32_mask(ay.count, _mm256_setzero_si256());
    store8(out->first_x.data() + i, ax.first), store8(out->first_y.data() + i, ay.first);
    store8(out->count_x.data() + i, _mm256_maskz_mov_epi32(on, ax.count));
    store8(out->count_y.data() + i, ay.count);
    store8(out->taps_x.data() + i, ax.offset), store8(out->taps_y.data() + i, ay.offset);
  }
}

#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif

static bool has_avx512_placement() {
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
         __builtin_cpu_supports("avx512dq");
}

// place_avx512() where the processor has AVX2 only: 4 footprints a vector, the same integers
// (the scalar placement, one footprint at a time, was about a quarter of the splat on fcc 10 M
// at 1024^2). A vector outside the last one's range of 4 sigma^2 takes its k from
// index_of_variance() lane by lane (rare along a published order); the entries are gathered.
__attribute__((target("avx2"))) static void place_avx2(const DensityKernelTable &table,
                                                       const int64_t *entries, const double *starts,
                                                       const double *px, const double *py,
                                                       const double *sigma2, int count, int width,
                                                       int height, DensityPlacements *out) {
  const __m256d far = _mm256_set1_pd(double(1 << 30)), sign = _mm256_set1_pd(-0.0);
  const __m256d half = _mm256_set1_pd(0.5), phases = _mm256_set1_pd(kDensityPhases);
  const __m128i last_phase = _mm_set1_epi32(kDensityPhases - 1), one = _mm_set1_epi32(1),
                zero = _mm_setzero_si128(), table_end = _mm_set1_epi32(kDensitySigmaCount);
  // An entry's low dwords (offsets) to the low half, its high ones (first, count) to the high.
  const __m256i split = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
  static_assert(kDensityPhases == 32, "k * 32 is a shift by 5");
  // One axis: place() and taps_at() of entries k (valid where the centre is near: elsewhere k
  // and the centre are 0, a valid entry whose result the caller drops).
  const auto axis = [&](__m256d centre, __m128i k, int size, __m128i *offset, __m128i *first,
                        __m128i *n) __attribute__((target("avx2"))) {
    const __m256d u = _mm256_sub_pd(centre, half);
    const __m256d b = _mm256_round_pd(u, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    const __m128i phase =
        _mm_min_epi32(_mm256_cvttpd_epi32(_mm256_mul_pd(_mm256_sub_pd(u, b), phases)), last_phase);
    const __m128i base = _mm256_cvttpd_epi32(b);
    const __m128i index = _mm_add_epi32(_mm_slli_epi32(k, 5), phase);
    // Entry: offset (bits 0-31), first (int16, bits 32-47), count (uint16, bits 48-63).
    const __m256i e = _mm256_permutevar8x32_epi32(
        _mm256_i32gather_epi64(reinterpret_cast<const long long *>(entries), index, 8), split);
    const __m128i off = _mm256_castsi256_si128(e), high = _mm256_extracti128_si256(e, 1);
    const __m128i lo = _mm_add_epi32(base, _mm_srai_epi32(_mm_slli_epi32(high, 16), 16));
    const __m128i hi = _mm_sub_epi32(_mm_add_epi32(lo, _mm_srli_epi32(high, 16)), one);
    const __m128i a = _mm_max_epi32(lo, zero);
    const __m128i z = _mm_min_epi32(hi, _mm_set1_epi32(size - 1));
    // Empty where hi < 0 or lo > size - 1: z - a + 1 <= 0 exactly then.
    *n = _mm_max_epi32(_mm_add_epi32(_mm_sub_epi32(z, a), one), zero);
    *offset = _mm_add_epi32(off, _mm_sub_epi32(a, lo));
    *first = a;
  };
  const auto store4 = [](int32_t * to, __m128i lanes) __attribute__((target("avx2"))) {
    _mm_storeu_si128(reinterpret_cast<__m128i *>(to), lanes);
  };
  int last = kDensitySigmaCount;
  __m256d lo = _mm256_set1_pd(HUGE_VAL), hi = lo;
  for (int i = 0; i + 4 <= count; i += 4) {
    const __m256d x = _mm256_mul_pd(_mm256_set1_pd(4.0), _mm256_loadu_pd(sigma2 + i));
    __m128i k;
    if (_mm256_movemask_pd(_mm256_and_pd(_mm256_cmp_pd(x, lo, _CMP_GE_OQ),
                                         _mm256_cmp_pd(x, hi, _CMP_LT_OQ))) == 0xf) {
      k = _mm_set1_epi32(last);
    } else {
      int lanes[4];
      for (int j = 0; j < 4; ++j) lanes[j] = table.index_of_variance(sigma2[i + j]);
      k = _mm_loadu_si128(reinterpret_cast<const __m128i *>(lanes));
      last = lanes[0];
      if (last < kDensitySigmaCount)
        lo = _mm256_set1_pd(starts[last]), hi = _mm256_set1_pd(starts[last + 1]);
      else
        lo = hi = _mm256_set1_pd(HUGE_VAL);
    }
    store4(out->k.data() + i, k);
    // The farness test (also false for NaN), then every far lane's centre and k at 0 so that
    // the conversions stay in range and the look-ups within the table.
    const __m256d cx = _mm256_loadu_pd(px + i), cy = _mm256_loadu_pd(py + i);
    const __m256d near = _mm256_and_pd(_mm256_cmp_pd(_mm256_andnot_pd(sign, cx), far, _CMP_LT_OQ),
                                       _mm256_cmp_pd(_mm256_andnot_pd(sign, cy), far, _CMP_LT_OQ));
    // The near lanes' masks as 32-bit lanes (the high dword of each 64-bit one), and with k.
    const __m128i live = _mm_and_si128(
        _mm256_extracti128_si256(_mm256_permutevar8x32_epi32(_mm256_castpd_si256(near), split), 1),
        _mm_cmplt_epi32(k, table_end));
    const __m256d live64 = _mm256_castsi256_pd(_mm256_cvtepi32_epi64(live));
    const __m128i kl = _mm_and_si128(live, k);
    __m128i offset_x, first_x, n_x, offset_y, first_y, n_y;
    axis(_mm256_and_pd(live64, cx), kl, width, &offset_x, &first_x, &n_x);
    axis(_mm256_and_pd(live64, cy), kl, height, &offset_y, &first_y, &n_y);
    const __m128i on =
        _mm_and_si128(live, _mm_and_si128(_mm_cmpgt_epi32(n_x, zero), _mm_cmpgt_epi32(n_y, zero)));
    store4(out->first_x.data() + i, first_x), store4(out->first_y.data() + i, first_y);
    store4(out->count_x.data() + i, _mm_and_si128(on, n_x));
    store4(out->count_y.data() + i, n_y);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(out->taps_x.data() + i), offset_x);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(out->taps_y.data() + i), offset_y);
  }
}

#endif

void DensityKernelTable::place_all(const double *px, const double *py, const double *sigma2,
                                   int count, int width, int height, DensityPlacements *out) const {
  out->resize(size_t(count));
  int done = 0;
#if defined(__x86_64__) && defined(__GNUC__)
  static const bool avx512 = has_avx512_placement(), avx2 = cpu_has_avx2();
  static_assert(sizeof(Entry) == 8, "an entry is gathered as one 64-bit word");
  if (avx512) {
    place_avx512(entries_.data(), below32_.data(), next_.data(), starts_.data(), px, py, sigma2,
                 count, width, height, out);
    done = count / 8 * 8;
  } else if (avx2) {
    place_avx2(*this, reinterpret_cast<const int64_t *>(entries_.data()), starts_.data(), px, py,
               sigma2, count, width, height, out);
    done = count / 4 * 4;
  }
#endif
  place_range(px, py, sigma2, done, count, width, height, out);
}

const DensityKernelTable &DensityKernelTable::get() {
  static const DensityKernelTable t;
  return t;
}

bool density_computed_taps(double centre, double sigma, int size, std::vector<uint16_t> *scratch,
                           AxisTaps *out) {
  const double reach = kCutoffSigmas * sigma;
  // Pixel k (centre k + 0.5) is inside the cut-off when |k + 0.5 - centre| <= reach. Clamped in
  // double before converting, so a huge footprint cannot overflow int.
  const double lo_d = std::ceil(centre - 0.5 - reach), hi_d = std::floor(centre - 0.5 + reach);
  if (hi_d < 0.0 || lo_d > double(size - 1) || lo_d > hi_d) return false;
  const int lo = int(std::max(lo_d, 0.0)), hi = int(std::min(hi_d, double(size - 1)));
  static const double integral_per_sigma =
      std::sqrt(2.0 * M_PI) * std::erf(kCutoffSigmas / std::sqrt(2.0));
  const double scale = kTapSum / (sigma * integral_per_sigma);
  const double a = 0.5 / (sigma * sigma);
  // Taps by the Gaussian's recurrence g(t + 1) = g(t) q(t), q(t + 1) = q(t) exp(-2a): three exps
  // per axis instead of one per tap.
  const double t = lo + 0.5 - centre;
  double g = std::exp(-t * t * a) * scale, q = std::exp(-(2.0 * t + 1.0) * a);
  const double qq = std::exp(-2.0 * a);
  scratch->resize(size_t(hi - lo + 1));
  for (uint16_t &v : *scratch) v = uint16_t(std::min(g + 0.5, 65535.0)), g *= q, q *= qq;
  out->taps = scratch->data();
  out->first = lo;
  out->count = hi - lo + 1;
  return true;
}

}  // namespace lantern
