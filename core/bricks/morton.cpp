#include "core/bricks/morton.h"

#include <cstring>

#include "core/common/cpu_features.h"
#include "core/common/stream_prefetch.h"

#if defined(__x86_64__) && defined(__SSE2__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_MORTON_AVX2 1
#include <immintrin.h>
#else
#define LANTERN_MORTON_AVX2 0
#endif

namespace lantern {
namespace {

bool minus_zero(double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b == uint64_t(1) << 63;
}

// prefix4 four points at a time, read from packed xyz.
bool packed_prefixes_by_four(const MortonQuantiser &q, const double *xyz, int64_t count,
                             uint32_t *out) {
  bool zero_sign = false;
  int64_t i = 0;
  for (; i + 4 <= count; i += 4) {
    double x[4], y[4], z[4];
    for (int k = 0; k < 4; ++k) {
      const double *p = xyz + 3 * (i + k);
      x[k] = p[0], y[k] = p[1], z[k] = p[2];
      zero_sign |= minus_zero(p[0]) | minus_zero(p[1]) | minus_zero(p[2]);
    }
    q.prefix4(x, y, z, out + i);
  }
  for (; i < count; ++i) {
    const double *p = xyz + 3 * i;
    zero_sign |= minus_zero(p[0]) | minus_zero(p[1]) | minus_zero(p[2]);
    out[i] = q.prefix({p[0], p[1], p[2]});
  }
  return zero_sign;
}

#if LANTERN_MORTON_AVX2
// axis() of four values: morton_detail::axis2's steps on four lanes (maxpd and minpd with the
// same operand order, so a NaN-free value clamps the same way; cvttpd2dq truncates the same).
__attribute__((target("avx2"))) inline __m128i axis_four(__m256d v, __m256d origin, __m256d scale) {
  __m256d s = _mm256_mul_pd(_mm256_sub_pd(v, origin), scale);
  s = _mm256_max_pd(s, _mm256_setzero_pd());
  s = _mm256_min_pd(s, _mm256_set1_pd(double(kMortonAxisMax)));
  return _mm256_cvttpd_epi32(s);
}

__attribute__((target("avx2"))) bool packed_prefixes_avx2(const MortonQuantiser &q,
                                                          const double *xyz, int64_t count,
                                                          uint32_t *out) {
  using namespace morton_detail;
  const __m256d lox = _mm256_set1_pd(q.lo.x), loy = _mm256_set1_pd(q.lo.y),
                loz = _mm256_set1_pd(q.lo.z), scale = _mm256_set1_pd(q.scale);
  const __m256i sign = _mm256_set1_epi64x(int64_t(uint64_t(1) << 63));
  __m256i zeros = _mm256_setzero_si256();
  int64_t i = 0;
  for (; i + 4 <= count; i += 4) {
    // a = x0 y0 z0 x1, b = y1 z1 x2 y2, c = z2 x3 y3 z3.
    const double *p = xyz + 3 * i;
    ask_stream_ahead(p, 2);  // core/common/stream_prefetch.h says why
    const __m256d a = _mm256_loadu_pd(p), b = _mm256_loadu_pd(p + 4), c = _mm256_loadu_pd(p + 8);
    const __m256i za = _mm256_cmpeq_epi64(_mm256_castpd_si256(a), sign);
    const __m256i zb = _mm256_cmpeq_epi64(_mm256_castpd_si256(b), sign);
    const __m256i zc = _mm256_cmpeq_epi64(_mm256_castpd_si256(c), sign);
    zeros = _mm256_or_si256(zeros, _mm256_or_si256(za, _mm256_or_si256(zb, zc)));
    const __m256d m1 = _mm256_permute2f128_pd(a, b, 0x30);  // x0 y0 x2 y2
    const __m256d m2 = _mm256_permute2f128_pd(a, c, 0x21);  // z0 x1 z2 x3
    const __m256d m3 = _mm256_permute2f128_pd(b, c, 0x30);  // y1 z1 y3 z3
    const __m256d x = _mm256_blend_pd(m1, m2, 0xA);
    const __m256d y = _mm256_shuffle_pd(m1, m3, 0x5);
    const __m256d z = _mm256_blend_pd(m2, m3, 0xA);
    const __m128i sx = spread_top11(axis_four(x, lox, scale));
    const __m128i sy = spread_top11(axis_four(y, loy, scale));
    const __m128i sz = spread_top11(axis_four(z, loz, scale));
    const __m128i key =
        _mm_or_si128(_mm_or_si128(_mm_slli_epi32(sx, 1), sy), _mm_srli_epi32(sz, 1));
    _mm_storeu_si128(reinterpret_cast<__m128i *>(out + i), key);
  }
  const bool tail = packed_prefixes_by_four(q, xyz + 3 * i, count - i, out + i);
  return tail || !_mm256_testz_si256(zeros, zeros);
}

// GCC 12 warns that the undefined pass-through its AVX-512 intrinsics start from is used
// uninitialized (the intrinsics themselves, not this code).
#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

// spread_top11 of eight lanes, each OR-and-mask step one ternary logic instruction.
__attribute__((target("avx512f,avx512vl"))) inline __m256i spread_top11_eight(__m256i v) {
  constexpr int kOrAnd = 0xA8;  // (a | b) & c
  v = _mm256_srli_epi32(v, 10);
  v = _mm256_ternarylogic_epi32(v, _mm256_slli_epi32(v, 16), _mm256_set1_epi32(0x070000FF), kOrAnd);
  v = _mm256_ternarylogic_epi32(v, _mm256_slli_epi32(v, 8), _mm256_set1_epi32(0x0700F00F), kOrAnd);
  v = _mm256_ternarylogic_epi32(v, _mm256_slli_epi32(v, 4), _mm256_set1_epi32(0x430C30C3), kOrAnd);
  v = _mm256_ternarylogic_epi32(v, _mm256_slli_epi32(v, 2), _mm256_set1_epi32(0x49249249), kOrAnd);
  return v;
}

// axis_four of eight values.
__attribute__((target("avx512f,avx512vl"))) inline __m256i axis_eight(__m512d v, __m512d origin,
                                                                      __m512d scale) {
  __m512d s = _mm512_mul_pd(_mm512_sub_pd(v, origin), scale);
  s = _mm512_max_pd(s, _mm512_setzero_pd());
  s = _mm512_min_pd(s, _mm512_set1_pd(double(kMortonAxisMax)));
  return _mm512_cvttpd_epi32(s);
}

// packed_prefixes_avx2's steps on eight points: x, y and z taken apart with two permutes each,
// the same arithmetic in doubles, and the bit spreading on eight 32-bit lanes. The same keys bit
// for bit. Why: the AVX2 kernel kept the build's first pass at about twice a streaming pass over
// the positions, most of it the spreading (13 operations an axis for four points, 9 here for
// eight).
__attribute__((target("avx512f,avx512vl"))) bool packed_prefixes_avx512(const MortonQuantiser &q,
                                                                        const double *xyz,
                                                                        int64_t count,
                                                                        uint32_t *out) {
  const __m512d lox = _mm512_set1_pd(q.lo.x), loy = _mm512_set1_pd(q.lo.y),
                loz = _mm512_set1_pd(q.lo.z), scale = _mm512_set1_pd(q.scale);
  const __m512i sign = _mm512_set1_epi64(int64_t(uint64_t(1) << 63));
  // Points 0-7's coordinates are doubles 0-23: a = 0-7, b = 8-15, c = 16-23. Each axis: its
  // first five or six from a and b, then the rest from c.
  const __m512i x_ab = _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0);
  const __m512i x_c = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13);
  const __m512i y_ab = _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0);
  const __m512i y_c = _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14);
  const __m512i z_ab = _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0);
  const __m512i z_c = _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15);
  __mmask8 zeros = 0;
  int64_t i = 0;
  for (; i + 8 <= count; i += 8) {
    const double *p = xyz + 3 * i;
    ask_stream_ahead(p, 3);
    const __m512d a = _mm512_loadu_pd(p), b = _mm512_loadu_pd(p + 8), c = _mm512_loadu_pd(p + 16);
    zeros |= _mm512_cmpeq_epi64_mask(_mm512_castpd_si512(a), sign) |
             _mm512_cmpeq_epi64_mask(_mm512_castpd_si512(b), sign) |
             _mm512_cmpeq_epi64_mask(_mm512_castpd_si512(c), sign);
    const __m512d x = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, x_ab, b), x_c, c);
    const __m512d y = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, y_ab, b), y_c, c);
    const __m512d z = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, z_ab, b), z_c, c);
    const __m256i sx = spread_top11_eight(axis_eight(x, lox, scale));
    const __m256i sy = spread_top11_eight(axis_eight(y, loy, scale));
    const __m256i sz = spread_top11_eight(axis_eight(z, loz, scale));
    constexpr int kOr3 = 0xFE;  // a | b | c
    const __m256i key =
        _mm256_ternarylogic_epi32(_mm256_slli_epi32(sx, 1), sy, _mm256_srli_epi32(sz, 1), kOr3);
    _mm256_storeu_si256(reinterpret_cast<__m256i *>(out + i), key);
  }
  const bool tail = packed_prefixes_by_four(q, xyz + 3 * i, count - i, out + i);
  return tail || zeros != 0;
}
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif

}  // namespace

bool packed_prefixes(const MortonQuantiser &q, const double *xyz, int64_t count, uint32_t *out,
                     PrefixKernel kernel) {
#if LANTERN_MORTON_AVX2
  if (kernel == PrefixKernel::kWidest && cpu_has_avx512_bw())
    return packed_prefixes_avx512(q, xyz, count, out);
  if (kernel != PrefixKernel::kPrefix4 && cpu_has_avx2())
    return packed_prefixes_avx2(q, xyz, count, out);
#endif
  (void)kernel;
  return packed_prefixes_by_four(q, xyz, count, out);
}

}  // namespace lantern
