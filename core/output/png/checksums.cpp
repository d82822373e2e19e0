#include "core/output/png/checksums.h"

#include <zlib.h>

#include <algorithm>

#include "core/common/cpu_features.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_CHECKSUMS_X86 1
#include <immintrin.h>
#else
#define LANTERN_CHECKSUMS_X86 0
#endif

namespace lantern {
namespace {

constexpr uint32_t kBase = 65521;  // the largest prime below 2^16
// The most bytes whose sums cannot overflow 32 bits before a reduction (zlib's NMAX, 5552),
// rounded down to whole 32-byte steps.
constexpr size_t kBlock = 5552 / 32 * 32;

#if LANTERN_CHECKSUMS_X86
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

#define LANTERN_CLMUL_TARGET __attribute__((target("pclmul,sse4.1")))

LANTERN_CLMUL_TARGET inline __m128i load16(const uint8_t *at) {
  return _mm_loadu_si128(reinterpret_cast<const __m128i *>(at));
}

// x folded forward over 64 or 16 bytes (k: that distance's pair of constants) onto `next`.
LANTERN_CLMUL_TARGET inline __m128i fold(__m128i x, __m128i k, __m128i next) {
  return _mm_xor_si128(
      _mm_xor_si128(_mm_clmulepi64_si128(x, k, 0x00), _mm_clmulepi64_si128(x, k, 0x11)), next);
}

// CRC-32 of n bytes (a multiple of 16, at least 64) by folding (Gopal et al.): four 128-bit lanes
// of the message are folded forward 64 bytes at a time by carry-less multiplication with
// x^(512 +- 32) mod P, then into one lane, then 16 bytes at a time, and the last 128 bits are
// reduced to 64, to 32, and by Barrett reduction to the remainder. In the bit-reflected domain of
// zlib's CRC, with its pre- and post-inversion done by the caller: `crc` and the result are
// inverted values.
LANTERN_CLMUL_TARGET uint32_t crc32_fold(uint32_t crc, const uint8_t *p, size_t n) {
  // x^(4*128+32) and x^(4*128-32) mod P, reflected and shifted (fold by 64 bytes); x^(128+32)
  // and x^(128-32) (fold by 16); x^64 (128 -> 64 bits); P and its Barrett quotient mu.
  const __m128i fold64 = _mm_set_epi64x(0x01c6e41596, 0x0154442bd4);
  const __m128i fold16 = _mm_set_epi64x(0x00ccaa009e, 0x01751997d0);
  const __m128i fold8 = _mm_set_epi64x(0, 0x0163cd6124);
  const __m128i barrett = _mm_set_epi64x(0x01f7011641, 0x01db710641);
  const __m128i low32 = _mm_setr_epi32(~0, 0, ~0, 0);
  __m128i x1 = _mm_xor_si128(load16(p), _mm_cvtsi32_si128(int(crc)));
  __m128i x2 = load16(p + 16), x3 = load16(p + 32), x4 = load16(p + 48);
  p += 64, n -= 64;
  for (; n >= 64; p += 64, n -= 64) {
    x1 = fold(x1, fold64, load16(p));
    x2 = fold(x2, fold64, load16(p + 16));
    x3 = fold(x3, fold64, load16(p + 32));
    x4 = fold(x4, fold64, load16(p + 48));
  }
  x1 = fold(fold(fold(x1, fold16, x2), fold16, x3), fold16, x4);
  for (; n >= 16; p += 16, n -= 16) x1 = fold(x1, fold16, load16(p));
  // 128 -> 64 bits, then 64 -> 32 + 32.
  x1 = _mm_xor_si128(_mm_srli_si128(x1, 8), _mm_clmulepi64_si128(x1, fold16, 0x10));
  x1 = _mm_xor_si128(_mm_srli_si128(x1, 4),
                     _mm_clmulepi64_si128(_mm_and_si128(x1, low32), fold8, 0x00));
  // Barrett reduction.
  __m128i t = _mm_clmulepi64_si128(_mm_and_si128(x1, low32), barrett, 0x10);
  t = _mm_clmulepi64_si128(_mm_and_si128(t, low32), barrett, 0x00);
  return uint32_t(_mm_extract_epi32(_mm_xor_si128(x1, t), 1));
}
#endif

}  // namespace

uint32_t crc32_extend(uint32_t crc, const uint8_t *data, size_t n) {
#if LANTERN_CHECKSUMS_X86
  if (n >= 64 && cpu_has_pclmul()) {
    const size_t whole = n / 16 * 16;
    crc = ~crc32_fold(~crc, data, whole);
    data += whole, n -= whole;
  }
#endif
  return uint32_t(crc32_z(crc, data, n));
}

uint32_t adler32_extend(uint32_t adler, const uint8_t *data, size_t n) {
#if LANTERN_CHECKSUMS_X86
  if (cpu_has_avx2()) return adler32_avx2(adler, data, n);
#endif
  return uint32_t(adler32_z(adler, data, n));
}

}  // namespace lantern
