#include "core/output/png/adler32.h"

#include <zlib.h>

#include <algorithm>

#include "core/common/cpu_features.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_ADLER32_AVX2 1
#include <immintrin.h>
#else
#define LANTERN_ADLER32_AVX2 0
#endif

namespace lantern {
namespace {

constexpr uint32_t kBase = 65521;  // the largest prime below 2^16
// The most bytes whose sums cannot overflow 32 bits before a reduction (zlib's NMAX, 5552),
// rounded down to whole 32-byte steps.
constexpr size_t kBlock = 5552 / 32 * 32;

#if LANTERN_ADLER32_AVX2
// The 32-bit lanes of v, summed.
__attribute__((target("avx2"))) uint64_t lane_sum(__m256i v) {
  const __m128i s = _mm_add_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
  const __m128i t = _mm_add_epi32(s, _mm_shuffle_epi32(s, 0x4E));
  return uint32_t(_mm_cvtsi128_si32(_mm_add_epi32(t, _mm_shuffle_epi32(t, 0xB1))));
}

// 32 bytes a step. Over a block of n bytes b_0 .. b_{n-1}, s1 grows by the sum of the bytes and
// s2 by n s1 + sum (n - i) b_i. Per step j: the byte sums (vpsadbw) go to `sum`; the bytes
// weighted 32 .. 1 (vpmaddubsw, vpmaddwd) to `weighted`; and before the step, the sums of the
// earlier steps to `earlier`, which counts each step's sum once per later step: sum (n - i) b_i
// = 32 earlier + weighted. Every lane stays below 2^32 within a block of kBlock bytes.
__attribute__((target("avx2"))) uint32_t adler32_avx2(uint32_t adler, const uint8_t *p, size_t n) {
  uint64_t s1 = adler & 0xFFFFu, s2 = adler >> 16;
  const __m256i weights =
      _mm256_setr_epi8(32, 31, 30, 29, 28, 27, 26, 25, 24, 23, 22, 21, 20, 19, 18, 17, 16, 15, 14,
                       13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1);
  const __m256i ones16 = _mm256_set1_epi16(1), zero = _mm256_setzero_si256();
  while (n >= 32) {
    const size_t block = std::min(n, kBlock) / 32 * 32;
    __m256i sum = zero, earlier = zero, weighted = zero;
    for (size_t k = 0; k < block; k += 32) {
      const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i *>(p + k));
      earlier = _mm256_add_epi32(earlier, sum);
      sum = _mm256_add_epi32(sum, _mm256_sad_epu8(v, zero));
      weighted =
          _mm256_add_epi32(weighted, _mm256_madd_epi16(_mm256_maddubs_epi16(v, weights), ones16));
    }
    s2 = (s2 + block * s1 + 32 * lane_sum(earlier) + lane_sum(weighted)) % kBase;
    s1 = (s1 + lane_sum(sum)) % kBase;
    p += block, n -= block;
  }
  for (; n > 0; --n) s1 += *p++, s2 += s1;  // fewer than 32: no overflow
  return uint32_t((s2 % kBase) << 16 | (s1 % kBase));
}
#endif

}  // namespace

uint32_t adler32_extend(uint32_t adler, const uint8_t *data, size_t n) {
#if LANTERN_ADLER32_AVX2
  if (cpu_has_avx2()) return adler32_avx2(adler, data, n);
#endif
  return uint32_t(adler32_z(adler, data, n));
}

}  // namespace lantern
