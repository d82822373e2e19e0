// Morton (z-order) keys: 21 bits per axis interleaved into a 63-bit key, x the most significant
// bit of each triple. Sorting by key orders particles along the z-order curve, so every run of
// keys sharing a 3l-bit prefix is one cell of an octree of depth l (Rizzi et al. 2015, §3.5).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

#include <glm/vec3.hpp>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lantern {

inline constexpr int kMortonBitsPerAxis = 21;
inline constexpr uint32_t kMortonAxisMax = (1u << kMortonBitsPerAxis) - 1;

// Spreads the low 21 bits of v so that bit k lands on bit 3k.
inline uint64_t morton_spread3(uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

// Inverse of morton_spread3: gathers bits 0, 3, 6, ... into the low 21 bits.
inline uint32_t morton_compact3(uint64_t v) {
  v &= 0x1249249249249249ull;
  v = (v ^ (v >> 2)) & 0x10c30c30c30c30c3ull;
  v = (v ^ (v >> 4)) & 0x100f00f00f00f00full;
  v = (v ^ (v >> 8)) & 0x1f0000ff0000ffull;
  v = (v ^ (v >> 16)) & 0x1f00000000ffffull;
  v = (v ^ (v >> 32)) & 0x1fffffull;
  return uint32_t(v);
}

inline uint64_t morton_encode(uint32_t x, uint32_t y, uint32_t z) {
  return morton_spread3(x) << 2 | morton_spread3(y) << 1 | morton_spread3(z);
}

// The key's top 32 bits (morton_encode(x, y, z) >> 31), which order particles down to cells of
// 1/2^10.67 of the box (the brick build's sort key): bits 10..20 of x and y and 11..20 of z,
// spread by a table of the 2048 11-bit values instead of five shift-and-mask steps per axis.
namespace morton_detail {
constexpr std::array<uint32_t, 2048> spread11_table() {
  std::array<uint32_t, 2048> t{};
  for (uint32_t v = 0; v < 2048; ++v)
    for (int b = 0; b < 11; ++b) t[v] |= ((v >> b) & 1u) << (3 * b);
  return t;
}
inline constexpr std::array<uint32_t, 2048> kSpread11 = spread11_table();
}  // namespace morton_detail

inline uint32_t morton_prefix(uint32_t x, uint32_t y, uint32_t z) {
  const auto &t = morton_detail::kSpread11;
  return t[x >> 10] << 1 | t[y >> 10] | t[z >> 10] >> 1;
}

// Maps positions in a box to integer lattice coordinates. The scale is the same on every axis so
// that octree cells are cubes (compact bricks), sized by the box's longest side.
struct MortonQuantiser {
  glm::dvec3 lo{0.0};
  double scale = 1.0;  // lattice steps per length unit

  static MortonQuantiser for_bounds(const glm::dvec3 &lo, const glm::dvec3 &hi) {
    const double side = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    MortonQuantiser q;
    q.lo = lo;
    // 0 also where the side is too short for a finite scale (below about 1e-299: denormal
    // coordinates), whose 0 x inf made NaN lattice coordinates.
    const double scale = side > 0.0 ? double(kMortonAxisMax) / side : 0.0;
    q.scale = scale <= std::numeric_limits<double>::max() ? scale : 0.0;
    return q;
  }
  uint32_t axis(double v, double origin) const {
    const double s = (v - origin) * scale;  // in [0, kMortonAxisMax] for points in the box
    // NaN (never from a finite scale and finite points) goes to 0, not through the conversion.
    return s > 0.0 ? (s < double(kMortonAxisMax) ? uint32_t(s) : kMortonAxisMax) : 0u;
  }
  uint64_t key(const glm::dvec3 &p) const {
    return morton_encode(axis(p.x, lo.x), axis(p.y, lo.y), axis(p.z, lo.z));
  }
  uint32_t prefix(const glm::dvec3 &p) const {  // key(p) >> 31
    return morton_prefix(axis(p.x, lo.x), axis(p.y, lo.y), axis(p.z, lo.z));
  }
  // prefix() of four points given by their coordinates: out[k] = prefix({x[k], y[k], z[k]}) for
  // points without NaN. The brick build's first pass spent most of its time in prefix() (a
  // scalar prefix cost about four times what streaming the point's 24 bytes does), so with SSE2
  // the four points go through the same steps two lanes at a time: the same subtraction,
  // multiplication and clamping in doubles (max(s, 0) and min(s, max) are axis()'s tests), the
  // truncation of cvttpd2dq (exact below 2^31), and the 11 top bits spread in 32-bit lanes
  // instead of read from the table. Tested against prefix() (bricks_test, Morton).
  void prefix4(const double x[4], const double y[4], const double z[4], uint32_t out[4]) const;
};

#if defined(__SSE2__)
namespace morton_detail {
// axis() of two values, to two 32-bit integers in the low half.
inline __m128i axis2(__m128d v, __m128d origin, __m128d scale) {
  __m128d s = _mm_mul_pd(_mm_sub_pd(v, origin), scale);
  s = _mm_max_pd(s, _mm_setzero_pd());                     // s > 0 ? s : 0
  s = _mm_min_pd(s, _mm_set1_pd(double(kMortonAxisMax)));  // s < max ? s : max
  return _mm_cvttpd_epi32(s);
}
// The top 11 of 21 bits of four axis values spread so that bit k lands on bit 3k (kSpread11).
inline __m128i spread_top11(__m128i v) {
  v = _mm_srli_epi32(v, 10);
  v = _mm_and_si128(_mm_or_si128(v, _mm_slli_epi32(v, 16)), _mm_set1_epi32(0x070000FF));
  v = _mm_and_si128(_mm_or_si128(v, _mm_slli_epi32(v, 8)), _mm_set1_epi32(0x0700F00F));
  v = _mm_and_si128(_mm_or_si128(v, _mm_slli_epi32(v, 4)), _mm_set1_epi32(0x430C30C3));
  v = _mm_and_si128(_mm_or_si128(v, _mm_slli_epi32(v, 2)), _mm_set1_epi32(0x49249249));
  return v;
}
inline __m128i axis4(const double v[4], double origin, double scale) {
  const __m128d o = _mm_set1_pd(origin), k = _mm_set1_pd(scale);
  return _mm_unpacklo_epi64(axis2(_mm_loadu_pd(v), o, k), axis2(_mm_loadu_pd(v + 2), o, k));
}
}  // namespace morton_detail

inline void MortonQuantiser::prefix4(const double x[4], const double y[4], const double z[4],
                                     uint32_t out[4]) const {
  using namespace morton_detail;
  const __m128i sx = spread_top11(axis4(x, lo.x, scale));
  const __m128i sy = spread_top11(axis4(y, lo.y, scale));
  const __m128i sz = spread_top11(axis4(z, lo.z, scale));
  const __m128i p = _mm_or_si128(_mm_or_si128(_mm_slli_epi32(sx, 1), sy), _mm_srli_epi32(sz, 1));
  _mm_storeu_si128(reinterpret_cast<__m128i *>(out), p);
}
#else
inline void MortonQuantiser::prefix4(const double x[4], const double y[4], const double z[4],
                                     uint32_t out[4]) const {
  for (int k = 0; k < 4; ++k) out[k] = prefix({x[k], y[k], z[k]});
}
#endif

// prefix() of `count` points given as packed xyz doubles (point k at xyz[3k], xyz[3k + 1],
// xyz[3k + 2]) into out[0, count), for points without NaN. Returns whether some coordinate is -0.
// The brick build's first pass over simulations that publish packed doubles (LAMMPS, most
// codes): with AVX2 the twelve doubles of four points come in three loads and are turned into x,
// y and z vectors in registers, where reading them one by one (prefix4's arrays) cost twice a
// streaming pass. Four lanes of the same operations as prefix4's two, or eight with AVX-512:
// the same keys, bit for bit.
enum class PrefixKernel {
  kWidest,  // AVX-512 where the processor has it, else AVX2, else prefix4
  kAvx2,    // AVX2 where the processor has it, else prefix4 (tests compare the kernels)
  kPrefix4,
};
bool packed_prefixes(const MortonQuantiser &q, const double *xyz, int64_t count, uint32_t *out,
                     PrefixKernel kernel = PrefixKernel::kWidest);

}  // namespace lantern
