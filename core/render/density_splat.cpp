#include "core/render/density_splat.h"

// No fused multiply-adds (core/render/CMakeLists.txt compiles this file with -ffp-contract=off):
// project_all's vectorised projection must round every operation as the baseline compilation
// (which has none) does, or the images would depend on the processor (GCC contracts a * b + c
// wherever the target has FMA, and AVX-512 implies it).

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/common/cpu_features.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define LANTERN_DENSITY_X86 1
#endif

namespace lantern {
namespace {

constexpr double kCutoffSigmas = 3.0;
constexpr double kPixelFilterSigma = 0.5;  // px: the reconstruction filter every footprint gets
// W of the header lies in [2^23, 2^24): times 256 or times an 8-bit colour it stays below 2^32,
// which is what a 32 x 32 -> 64-bit vector multiply (SSE2 pmuludq) takes.
constexpr int kWeightMantissaBits = 24;
// The widest footprint row (pixels) of the weight-1 loop below: three registers of two pixels.
constexpr int kUnitMaxWidth = 6;

// One footprint's factors: the four per-channel multipliers M (W 256, W c0, W c1, W c2, each
// < 2^32), and the shift that takes M p (p = tx ty) to 2^-24 units of weight (+ 8 bits for the
// 256 that lets the colour channels share it).
struct Factors {
  uint64_t m[4];
  int shift;
};

// The pixel loops: per pixel p = tx ty (a 32-bit product), then per channel (M p + half) >>
// shift, added into the int64 sums. The four channels of a pixel are one 256-bit vector (AVX2),
// two 128-bit ones (SSE2), or half a 512-bit one (AVX-512, two pixels a register); integer
// arithmetic, so every path gives the same bits. With the kernel table this replaced double
// products, float->int conversions and an exact rounded / 255 per colour channel: fcc 1 M at
// 1024^2, r 0.5, 175 -> 128 ms CPU for the two together.
void add_scalar(int64_t *image, int pitch, int channels, const AxisTaps &ax, const AxisTaps &ay,
                const Factors &f) {
  const uint64_t half = uint64_t(1) << (f.shift - 1);
  for (int y = 0; y < ay.count; ++y) {
    int64_t *out =
        image + (size_t(ay.first + y) * size_t(pitch) + size_t(ax.first)) * size_t(channels);
    const uint32_t ty = ay.taps[y];
    for (int i = 0; i < ax.count; ++i, out += channels) {
      const uint64_t p = uint64_t(uint32_t(ax.taps[i]) * ty);
      for (int c = 0; c < channels; ++c) out[c] += int64_t((f.m[c] * p + half) >> f.shift);
    }
  }
}

void add4_scalar(int64_t *image, int pitch, const AxisTaps &ax, const AxisTaps &ay,
                 const uint64_t m[4], int shift) {
  add_scalar(image, pitch, 4, ax, ay, Factors{{m[0], m[1], m[2], m[3]}, shift});
}

#ifdef LANTERN_DENSITY_X86
void add4_sse2(int64_t *image, int pitch, const AxisTaps &ax, const AxisTaps &ay,
               const uint64_t m[4], int shift) {
  const __m128i m01 = _mm_set_epi64x(int64_t(m[1]), int64_t(m[0]));
  const __m128i m23 = _mm_set_epi64x(int64_t(m[3]), int64_t(m[2]));
  const __m128i half = _mm_set1_epi64x(int64_t(1) << (shift - 1));
  const __m128i by = _mm_cvtsi32_si128(shift);
  for (int y = 0; y < ay.count; ++y) {
    auto *out = reinterpret_cast<__m128i *>(
        image + (size_t(ay.first + y) * size_t(pitch) + size_t(ax.first)) * 4);
    const uint32_t ty = ay.taps[y];
    for (int i = 0; i < ax.count; ++i, out += 2) {
      const __m128i p = _mm_set1_epi64x(int64_t(uint32_t(ax.taps[i]) * ty));
      const __m128i a = _mm_srl_epi64(_mm_add_epi64(_mm_mul_epu32(m01, p), half), by);
      const __m128i b = _mm_srl_epi64(_mm_add_epi64(_mm_mul_epu32(m23, p), half), by);
      _mm_storeu_si128(out, _mm_add_epi64(_mm_loadu_si128(out), a));
      _mm_storeu_si128(out + 1, _mm_add_epi64(_mm_loadu_si128(out + 1), b));
    }
  }
}

__attribute__((target("avx2"))) void add4_avx2(int64_t *image, int pitch, const AxisTaps &ax,
                                               const AxisTaps &ay, const uint64_t m[4], int shift) {
  const __m256i mv = _mm256_set_epi64x(int64_t(m[3]), int64_t(m[2]), int64_t(m[1]), int64_t(m[0]));
  const __m256i half = _mm256_set1_epi64x(int64_t(1) << (shift - 1));
  const __m128i by = _mm_cvtsi32_si128(shift);
  for (int y = 0; y < ay.count; ++y) {
    auto *out = reinterpret_cast<__m256i *>(
        image + (size_t(ay.first + y) * size_t(pitch) + size_t(ax.first)) * 4);
    const uint32_t ty = ay.taps[y];
    for (int i = 0; i < ax.count; ++i, ++out) {
      const __m256i p = _mm256_set1_epi64x(int64_t(uint32_t(ax.taps[i]) * ty));
      const __m256i v = _mm256_srl_epi64(_mm256_add_epi64(_mm256_mul_epu32(mv, p), half), by);
      _mm256_storeu_si256(out, _mm256_add_epi64(_mm256_loadu_si256(out), v));
    }
  }
}

// GCC 12 warns that the undefined pass-through its AVX-512 intrinsics start from "may be used
// uninitialized" (the intrinsics themselves, not this code).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// Footprints at most 4 pixels wide (every sub-pixel sphere: sigma under about 1.2 px), two
// pixels per register: a row's 4 products tx ty in one multiply, each pair of pixels' four
// channels in one, masked to the footprint (so nothing is read or written beyond it).
__attribute__((target("avx512f,avx512vl,avx512dq,avx512bw"))) void add4_avx512(
    int64_t *image, int pitch, const AxisTaps &ax, const AxisTaps &ay, const uint64_t m[4],
    int shift) {
  if (ax.count > 4) return add4_avx2(image, pitch, ax, ay, m, shift);
  const __m512i mv = _mm512_set_epi64(int64_t(m[3]), int64_t(m[2]), int64_t(m[1]), int64_t(m[0]),
                                      int64_t(m[3]), int64_t(m[2]), int64_t(m[1]), int64_t(m[0]));
  const __m512i half = _mm512_set1_epi64(int64_t(1) << (shift - 1));
  const __m128i by = _mm_cvtsi32_si128(shift);
  // The row's taps, zero beyond the footprint (a masked load reads nothing past it).
  const __m256i tx =
      _mm256_cvtepu16_epi64(_mm_maskz_loadu_epi16(__mmask8((1u << ax.count) - 1), ax.taps));
  const __m512i first_pair = _mm512_set_epi64(1, 1, 1, 1, 0, 0, 0, 0);
  const __m512i second_pair = _mm512_set_epi64(3, 3, 3, 3, 2, 2, 2, 2);
  const __mmask8 first = ax.count >= 2 ? 0xff : 0x0f;
  const __mmask8 second = ax.count >= 4 ? 0xff : ax.count == 3 ? 0x0f : 0x00;
  for (int y = 0; y < ay.count; ++y) {
    int64_t *out = image + (size_t(ay.first + y) * size_t(pitch) + size_t(ax.first)) * 4;
    // tx ty < 2^32: taps are below 2^16 (a single tap of the whole 2^16 never occurs).
    const __m512i p =
        _mm512_zextsi256_si512(_mm256_mul_epu32(tx, _mm256_set1_epi64x(int64_t(ay.taps[y]))));
    const __m512i a = _mm512_srl_epi64(
        _mm512_add_epi64(_mm512_mul_epu32(mv, _mm512_permutexvar_epi64(first_pair, p)), half), by);
    _mm512_mask_storeu_epi64(out, first, _mm512_add_epi64(_mm512_maskz_loadu_epi64(first, out), a));
    if (second == 0) continue;
    const __m512i b = _mm512_srl_epi64(
        _mm512_add_epi64(_mm512_mul_epu32(mv, _mm512_permutexvar_epi64(second_pair, p)), half), by);
    _mm512_mask_storeu_epi64(out + 8, second,
                             _mm512_add_epi64(_mm512_maskz_loadu_epi64(second, out + 8), b));
  }
}

// Weight-1 footprints (every particle without level of detail) of a four-channel image. Weight 1
// has W = 2^23 and shift 39 (set_factors), so a channel's share is (2^23 c p + 2^38) >> 39 =
// (c p + 2^15) >> 16 with c = 256 for the weight and the colour component for the others, the
// same integers; and c p = (c tx) ty, so the 24-bit products c tx of a footprint's row of taps
// are made once per footprint (two pixels' four channels a register, up to three registers for
// 6 pixels) and each image row costs one 32 x 32 -> 64-bit multiply, add and shift per
// register: no per-row permutes of the general loop (which multiplies the 32-bit p = tx ty by
// 64-bit factors). Taps beyond the footprint are zero, and the masks keep the loads and stores
// within it.
#define LANTERN_DENSITY_AVX512 __attribute__((target("avx512f,avx512vl,avx512dq,avx512bw")))

// c per channel, for both pixels of a register: (256, c0, c1, c2, 256, c0, c1, c2).
LANTERN_DENSITY_AVX512 inline __m512i unit_factors(const Rgb8 &color) {
  const uint32_t bytes =
      uint32_t(color[0]) << 8 | uint32_t(color[1]) << 16 | uint32_t(color[2]) << 24;
  const __m512i v = _mm512_cvtepu8_epi64(_mm_set1_epi32(int(bytes)));
  return _mm512_mask_mov_epi64(v, 0x11, _mm512_set1_epi64(256));
}

// One weight-1 footprint of 1 .. kUnitMaxWidth pixels a row, taps tx (count_x of them) x ty.
LANTERN_DENSITY_AVX512 inline __attribute__((always_inline)) void add_unit(
    int64_t *image, size_t row_pitch, const uint16_t *tx_taps, int first_x, int count_x,
    const uint16_t *ty, int first_y, int count_y, __m512i c) {
  const __m512i tx =
      _mm512_cvtepu16_epi64(_mm_maskz_loadu_epi16(__mmask8((1u << count_x) - 1), tx_taps));
  const __m512i pair = _mm512_set_epi64(1, 1, 1, 1, 0, 0, 0, 0);
  const __m512i two = _mm512_set1_epi64(2);
  const __m512i rnd = _mm512_set1_epi64(int64_t(1) << 15);
  // c tx < 2^24 and ty < 2^16: the low 32 bits of each lane are the whole factor.
  const __m512i a0 = _mm512_mul_epu32(c, _mm512_permutexvar_epi64(pair, tx));
  const __m512i a1 = _mm512_mul_epu32(c, _mm512_permutexvar_epi64(_mm512_add_epi64(pair, two), tx));
  const uint32_t lanes = (uint32_t(1) << (4 * count_x)) - 1;
  const __mmask8 m0 = __mmask8(lanes), m1 = __mmask8(lanes >> 8);
  int64_t *row = image + size_t(first_y) * row_pitch + size_t(first_x) * 4;
  if (count_x <= 4) {
    for (int y = 0; y < count_y; ++y, row += row_pitch) {
      const __m512i t = _mm512_set1_epi64(int64_t(ty[y]));
      const __m512i q0 = _mm512_srli_epi64(_mm512_add_epi64(_mm512_mul_epu32(a0, t), rnd), 16);
      _mm512_mask_storeu_epi64(row, m0, _mm512_add_epi64(_mm512_maskz_loadu_epi64(m0, row), q0));
      if (m1 == 0) continue;
      const __m512i q1 = _mm512_srli_epi64(_mm512_add_epi64(_mm512_mul_epu32(a1, t), rnd), 16);
      _mm512_mask_storeu_epi64(row + 8, m1,
                               _mm512_add_epi64(_mm512_maskz_loadu_epi64(m1, row + 8), q1));
    }
    return;
  }
  const __m512i a2 = _mm512_mul_epu32(
      c, _mm512_permutexvar_epi64(_mm512_add_epi64(pair, _mm512_add_epi64(two, two)), tx));
  const __mmask8 m2 = __mmask8(lanes >> 16);
  for (int y = 0; y < count_y; ++y, row += row_pitch) {
    const __m512i t = _mm512_set1_epi64(int64_t(ty[y]));
    const __m512i q0 = _mm512_srli_epi64(_mm512_add_epi64(_mm512_mul_epu32(a0, t), rnd), 16);
    const __m512i q1 = _mm512_srli_epi64(_mm512_add_epi64(_mm512_mul_epu32(a1, t), rnd), 16);
    const __m512i q2 = _mm512_srli_epi64(_mm512_add_epi64(_mm512_mul_epu32(a2, t), rnd), 16);
    _mm512_storeu_si512(row, _mm512_add_epi64(_mm512_loadu_si512(row), q0));
    _mm512_storeu_si512(row + 8, _mm512_add_epi64(_mm512_loadu_si512(row + 8), q1));
    _mm512_mask_storeu_epi64(row + 16, m2,
                             _mm512_add_epi64(_mm512_maskz_loadu_epi64(m2, row + 16), q2));
  }
}

// add_unit() of every footprint k in [0, count) that is in front, in the table and at most
// kUnitMaxWidth pixels wide on the image (the caller deposits the others). Returns how many;
// adds their pixels to *pixels and the number of the others in front that touch the image or
// lie beyond the table (those the caller still has to deposit) to *rest.
LANTERN_DENSITY_AVX512 int64_t add_units_placed(int64_t *image, int pitch_px, const uint16_t *taps,
                                                const DensityPlacements &p, const uint8_t *in_front,
                                                const Rgb8 *color, int count, int64_t *pixels,
                                                int64_t *rest, const DensityStreamAhead &next) {
  const size_t pitch = size_t(pitch_px) * 4;
  int64_t done = 0, written = 0, others = 0;
  for (int i = 0; i < count; ++i) {
    const auto at = size_t(i);
    // One cache line a footprint of what the caller reads next (the next batch's particles),
    // asked for between the pixel work so that its misses overlap it.
    for (int s = 0; s < 2; ++s)
      if (size_t(i) * 64 < next.bytes[s]) __builtin_prefetch(next.at[s] + size_t(i) * 64, 0, 3);
    // No prefetch of the image rows of the footprints ahead (this loop and the AVX2 one below
    // had one): on an AVX-512 EPYC, fcc 10 M at 1024^2, the frame was 6 % faster without it
    // (median of 20 alternated rounds; 10 % on a quiet host), though more variable on a busy one
    // (tests/bench/culling/results/density/README.md, 4 December 2026).
    const int cx = p.count_x[at];
    if (!in_front[at]) continue;
    if (p.k[at] >= kDensitySigmaCount || cx > kUnitMaxWidth) {
      ++others;
      continue;
    }
    if (cx == 0) continue;
    const int cy = p.count_y[at];
    add_unit(image, pitch, taps + p.taps_x[at], p.first_x[at], cx, taps + p.taps_y[at],
             p.first_y[at], cy, unit_factors(color[i]));
    ++done, written += int64_t(cx) * cy;
  }
  *pixels += written;
  *rest = others;
  return done;
}

// add_unit() of the records of at most kUnitMaxWidth pixels a row; the caller deposits the rest.
LANTERN_DENSITY_AVX512 void add_units_binned(int64_t *image, int pitch_px, const uint16_t *taps,
                                             const std::vector<DensityRecord> &records,
                                             int64_t *pixels) {
  const size_t pitch = size_t(pitch_px) * 4;
  int64_t written = 0;
  for (const DensityRecord &r : records) {
    if (r.count_x > kUnitMaxWidth) continue;
    add_unit(image, pitch, taps + r.taps_x, r.first_x, r.count_x, taps + r.taps_y, r.first_y,
             r.count_y, unit_factors({r.color[0], r.color[1], r.color[2]}));
    written += int64_t(r.count_x) * r.count_y;
  }
  *pixels += written;
}

// add_unit() in AVX2, one pixel's four channels a register, for a footprint kWidth pixels wide:
// the products c tx once per footprint, then per pixel of a row one multiply, add, shift (no
// per-pixel product tx ty and broadcast of add4_avx2). The same integers: weight 1 as above.
template <int kWidth>
__attribute__((target("avx2"), always_inline)) inline void add_unit_avx2(
    int64_t *image, size_t row_pitch, const uint16_t *tx, int first_x, const uint16_t *ty,
    int first_y, int count_y, __m256i c) {
  __m256i a[kWidth];
  // c tx < 2^24 and ty < 2^16: the low 32 bits of each lane are the whole factor.
  for (int i = 0; i < kWidth; ++i) a[i] = _mm256_mul_epu32(c, _mm256_set1_epi32(tx[i]));
  const __m256i rnd = _mm256_set1_epi64x(int64_t(1) << 15);
  int64_t *row = image + size_t(first_y) * row_pitch + size_t(first_x) * 4;
  for (int y = 0; y < count_y; ++y, row += row_pitch) {
    const __m256i t = _mm256_set1_epi32(ty[y]);
    for (int i = 0; i < kWidth; ++i) {
      auto *out = reinterpret_cast<__m256i *>(row + 4 * i);
      const __m256i q = _mm256_srli_epi64(_mm256_add_epi64(_mm256_mul_epu32(a[i], t), rnd), 16);
      _mm256_storeu_si256(out, _mm256_add_epi64(_mm256_loadu_si256(out), q));
    }
  }
}

// add_units_placed() in AVX2 (add_unit_avx2 per footprint, a loop unrolled for each width).
__attribute__((target("avx2"))) int64_t add_units_placed_avx2(
    int64_t *image, int pitch_px, const uint16_t *taps, const DensityPlacements &p,
    const uint8_t *in_front, const Rgb8 *color, int count, int64_t *pixels, int64_t *rest,
    const DensityStreamAhead &next) {
  const size_t pitch = size_t(pitch_px) * 4;
  int64_t done = 0, written = 0, others = 0;
  for (int i = 0; i < count; ++i) {
    const auto at = size_t(i);
    for (int s = 0; s < 2; ++s)
      if (size_t(i) * 64 < next.bytes[s]) __builtin_prefetch(next.at[s] + size_t(i) * 64, 0, 3);
    const int cx = p.count_x[at];
    if (!in_front[at]) continue;
    if (p.k[at] >= kDensitySigmaCount || cx > kUnitMaxWidth) {
      ++others;
      continue;
    }
    if (cx == 0) continue;
    const int cy = p.count_y[at];
    const __m256i c = _mm256_setr_epi64x(256, color[i][0], color[i][1], color[i][2]);
    const uint16_t *tx = taps + p.taps_x[at], *ty = taps + p.taps_y[at];
    const int x0 = p.first_x[at], y0 = p.first_y[at];
    switch (cx) {
      case 1:
        add_unit_avx2<1>(image, pitch, tx, x0, ty, y0, cy, c);
        break;
      case 2:
        add_unit_avx2<2>(image, pitch, tx, x0, ty, y0, cy, c);
        break;
      case 3:
        add_unit_avx2<3>(image, pitch, tx, x0, ty, y0, cy, c);
        break;
      case 4:
        add_unit_avx2<4>(image, pitch, tx, x0, ty, y0, cy, c);
        break;
      case 5:
        add_unit_avx2<5>(image, pitch, tx, x0, ty, y0, cy, c);
        break;
      default:
        add_unit_avx2<6>(image, pitch, tx, x0, ty, y0, cy, c);
        break;
    }
    static_assert(kUnitMaxWidth == 6, "a case per width");
    ++done, written += int64_t(cx) * cy;
  }
  *pixels += written;
  *rest = others;
  return done;
}

#endif

// The world -> view transform and project() of DensitySplatter, over arrays: written as one
// loop without branches (the projection type is hoisted) so the compiler vectorises it, with
// every operation in project()'s and glm's order (view = (m0 x + m1 y) + (m2 z + m3)), so the
// same bits.
template <bool kOrthographic, bool kPerParticle>
inline __attribute__((always_inline)) void project_loop(
    const ViewGeometry &g, const double *__restrict x, const double *__restrict y,
    const double *__restrict z, const double *__restrict r, double radius, double scale, int count,
    DensityFootprints *out) {
  const glm::dmat4 &m = g.view;
  const double ppu = 0.5 * g.height * g.sy, w = g.width, h = g.height, near = g.near_plane;
  double *__restrict px = out->px.data(), *__restrict py = out->py.data(),
                     *__restrict sigma2 = out->sigma2.data();
  uint8_t *__restrict in_front = out->in_front.data();
  for (int k = 0; k < count; ++k) {
    const double cx = (m[0][0] * x[k] + m[1][0] * y[k]) + (m[2][0] * z[k] + m[3][0]);
    const double cy = (m[0][1] * x[k] + m[1][1] * y[k]) + (m[2][1] * z[k] + m[3][1]);
    const double cz = (m[0][2] * x[k] + m[1][2] * y[k]) + (m[2][2] * z[k] + m[3][2]);
    const double d = -cz;
    in_front[k] = d > near;
    const double inv_d = kOrthographic ? 1.0 : 1.0 / d;
    const double x_ndc = kOrthographic ? g.sx * cx + g.tx : g.sx * cx * inv_d;
    const double y_ndc = kOrthographic ? g.sy * cy + g.ty : g.sy * cy * inv_d;
    px[k] = 0.5 * (x_ndc + 1.0) * w;
    py[k] = 0.5 * (1.0 - y_ndc) * h;
    const double s = (kPerParticle ? r[k] * scale : radius * scale) / 3.0 * ppu * inv_d;
    sigma2[k] = s * s + 0.25;
  }
}

void project_portable(const ViewGeometry &g, const double *x, const double *y, const double *z,
                      const double *r, double radius, double scale, int count,
                      DensityFootprints *out) {
  if (g.orthographic)
    r ? project_loop<true, true>(g, x, y, z, r, radius, scale, count, out)
      : project_loop<true, false>(g, x, y, z, r, radius, scale, count, out);
  else
    r ? project_loop<false, true>(g, x, y, z, r, radius, scale, count, out)
      : project_loop<false, false>(g, x, y, z, r, radius, scale, count, out);
}

#ifdef LANTERN_DENSITY_X86
__attribute__((target("avx2"))) void project_avx2(const ViewGeometry &g, const double *x,
                                                  const double *y, const double *z, const double *r,
                                                  double radius, double scale, int count,
                                                  DensityFootprints *out) {
  if (g.orthographic)
    r ? project_loop<true, true>(g, x, y, z, r, radius, scale, count, out)
      : project_loop<true, false>(g, x, y, z, r, radius, scale, count, out);
  else
    r ? project_loop<false, true>(g, x, y, z, r, radius, scale, count, out)
      : project_loop<false, false>(g, x, y, z, r, radius, scale, count, out);
}
#endif

#ifdef LANTERN_DENSITY_X86
// One coordinate of the view transform, (c0 x + c1 y) + (c2 z + c3), as glm rounds it.
LANTERN_DENSITY_AVX512 inline __m512d view_row(__m512d c0, __m512d c1, __m512d c2, __m512d c3,
                                               __m512d x, __m512d y, __m512d z) {
  return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(c0, x), _mm512_mul_pd(c1, y)),
                       _mm512_add_pd(_mm512_mul_pd(c2, z), c3));
}

// project_loop<kOrthographic, false>() of 8 particles a vector, read from interleaved x, y, z
// doubles: every operation in the loop's order (this file has no contraction into fused
// multiply-adds), so the same bits. False when a coordinate is not finite.
template <bool kOrthographic>
LANTERN_DENSITY_AVX512 bool project_xyz_avx512(const ViewGeometry &g, const unsigned char *xyz,
                                               double radius, int count, DensityFootprints *out) {
  const glm::dmat4 &m = g.view;
  const __m512d m00 = _mm512_set1_pd(m[0][0]), m10 = _mm512_set1_pd(m[1][0]),
                m20 = _mm512_set1_pd(m[2][0]), m30 = _mm512_set1_pd(m[3][0]);
  const __m512d m01 = _mm512_set1_pd(m[0][1]), m11 = _mm512_set1_pd(m[1][1]),
                m21 = _mm512_set1_pd(m[2][1]), m31 = _mm512_set1_pd(m[3][1]);
  const __m512d m02 = _mm512_set1_pd(m[0][2]), m12 = _mm512_set1_pd(m[1][2]),
                m22 = _mm512_set1_pd(m[2][2]), m32 = _mm512_set1_pd(m[3][2]);
  const __m512d sx = _mm512_set1_pd(g.sx), sy = _mm512_set1_pd(g.sy), tx = _mm512_set1_pd(g.tx),
                ty = _mm512_set1_pd(g.ty);
  const __m512d w = _mm512_set1_pd(double(g.width)), h = _mm512_set1_pd(double(g.height)),
                near = _mm512_set1_pd(g.near_plane);
  const __m512d one = _mm512_set1_pd(1.0), half = _mm512_set1_pd(0.5), zero = _mm512_setzero_pd();
  // radius * scale / 3 * ppu, as the loop rounds it (scale 1).
  const __m512d r3 = _mm512_set1_pd(radius * 1.0 / 3.0),
                ppu = _mm512_set1_pd(0.5 * g.height * g.sy);
  const __m512d quarter = _mm512_set1_pd(0.25), sign = _mm512_set1_pd(-0.0);
  // Three vectors hold x0 y0 z0 x1 ... z7: lanes 0-15 of (a, b) then 0-7 of c.
  const __m512i pick_x = _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0);
  const __m512i pick_y = _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0);
  const __m512i pick_z = _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0);
  const __m512i last_x = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 8 + 2, 8 + 5);
  const __m512i last_y = _mm512_setr_epi64(0, 1, 2, 3, 4, 8 + 0, 8 + 3, 8 + 6);
  const __m512i last_z = _mm512_setr_epi64(0, 1, 2, 3, 4, 8 + 1, 8 + 4, 8 + 7);
  double *px = out->px.data(), *py = out->py.data(), *sigma2 = out->sigma2.data();
  uint8_t *in_front = out->in_front.data();
  __mmask8 finite = 0xff;
  for (int k = 0; k < count; k += 8) {
    const auto *p = reinterpret_cast<const double *>(xyz + size_t(k) * 24);
    const __m512d a = _mm512_loadu_pd(p), b = _mm512_loadu_pd(p + 8), c = _mm512_loadu_pd(p + 16);
    const __m512d x = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, pick_x, b), last_x, c);
    const __m512d y = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, pick_y, b), last_y, c);
    const __m512d z = _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, pick_z, b), last_z, c);
    // x - x is 0 exactly when x is finite.
    finite &= _mm512_cmp_pd_mask(_mm512_sub_pd(x, x), zero, _CMP_EQ_OQ) &
              _mm512_cmp_pd_mask(_mm512_sub_pd(y, y), zero, _CMP_EQ_OQ) &
              _mm512_cmp_pd_mask(_mm512_sub_pd(z, z), zero, _CMP_EQ_OQ);
    const __m512d cx = view_row(m00, m10, m20, m30, x, y, z);
    const __m512d cy = view_row(m01, m11, m21, m31, x, y, z);
    const __m512d d = _mm512_xor_pd(view_row(m02, m12, m22, m32, x, y, z), sign);
    const __mmask8 front = _mm512_cmp_pd_mask(d, near, _CMP_GT_OQ);
    const __m512d inv_d = kOrthographic ? one : _mm512_div_pd(one, d);
    const __m512d x_ndc = kOrthographic ? _mm512_add_pd(_mm512_mul_pd(sx, cx), tx)
                                        : _mm512_mul_pd(_mm512_mul_pd(sx, cx), inv_d);
    const __m512d y_ndc = kOrthographic ? _mm512_add_pd(_mm512_mul_pd(sy, cy), ty)
                                        : _mm512_mul_pd(_mm512_mul_pd(sy, cy), inv_d);
    _mm512_storeu_pd(px + k, _mm512_mul_pd(_mm512_mul_pd(half, _mm512_add_pd(x_ndc, one)), w));
    _mm512_storeu_pd(py + k, _mm512_mul_pd(_mm512_mul_pd(half, _mm512_sub_pd(one, y_ndc)), h));
    const __m512d s = _mm512_mul_pd(_mm512_mul_pd(r3, ppu), inv_d);
    _mm512_storeu_pd(sigma2 + k, _mm512_add_pd(_mm512_mul_pd(s, s), quarter));
    _mm_storel_epi64(reinterpret_cast<__m128i *>(in_front + k), _mm_maskz_set1_epi8(front, 1));
  }
  return finite == 0xff;
}

// view_row() in AVX2.
__attribute__((target("avx2"))) inline __m256d view_row_avx2(__m256d c0, __m256d c1, __m256d c2,
                                                             __m256d c3, __m256d x, __m256d y,
                                                             __m256d z) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(c0, x), _mm256_mul_pd(c1, y)),
                       _mm256_add_pd(_mm256_mul_pd(c2, z), c3));
}

// project_xyz_avx512() where the processor has AVX2 only: 4 particles a vector, the same
// operations in the same order, so the same bits (without it the pass copies every position
// into arrays first, about a sixth of the pass on fcc 10 M at 1024^2).
template <bool kOrthographic>
__attribute__((target("avx2"))) bool project_xyz_avx2(const ViewGeometry &g,
                                                      const unsigned char *xyz, double radius,
                                                      int count, DensityFootprints *out) {
  const glm::dmat4 &m = g.view;
  const __m256d m00 = _mm256_set1_pd(m[0][0]), m10 = _mm256_set1_pd(m[1][0]),
                m20 = _mm256_set1_pd(m[2][0]), m30 = _mm256_set1_pd(m[3][0]);
  const __m256d m01 = _mm256_set1_pd(m[0][1]), m11 = _mm256_set1_pd(m[1][1]),
                m21 = _mm256_set1_pd(m[2][1]), m31 = _mm256_set1_pd(m[3][1]);
  const __m256d m02 = _mm256_set1_pd(m[0][2]), m12 = _mm256_set1_pd(m[1][2]),
                m22 = _mm256_set1_pd(m[2][2]), m32 = _mm256_set1_pd(m[3][2]);
  const __m256d sx = _mm256_set1_pd(g.sx), sy = _mm256_set1_pd(g.sy), tx = _mm256_set1_pd(g.tx),
                ty = _mm256_set1_pd(g.ty);
  const __m256d w = _mm256_set1_pd(double(g.width)), h = _mm256_set1_pd(double(g.height)),
                near = _mm256_set1_pd(g.near_plane);
  const __m256d one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5), zero = _mm256_setzero_pd();
  const __m256d r3 = _mm256_set1_pd(radius * 1.0 / 3.0),
                ppu = _mm256_set1_pd(0.5 * g.height * g.sy);
  const __m256d quarter = _mm256_set1_pd(0.25), sign = _mm256_set1_pd(-0.0);
  double *px = out->px.data(), *py = out->py.data(), *sigma2 = out->sigma2.data();
  uint8_t *in_front = out->in_front.data();
  __m256d finite = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  for (int k = 0; k < count; k += 4) {
    const auto *p = reinterpret_cast<const double *>(xyz + size_t(k) * 24);
    // 128-bit halves: (x0 y0 | x2 y2), (z0 x1 | z2 x3), (y1 z1 | y3 z3).
    const __m256d a =
        _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p)), _mm_loadu_pd(p + 6), 1);
    const __m256d b =
        _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p + 2)), _mm_loadu_pd(p + 8), 1);
    const __m256d c =
        _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p + 4)), _mm_loadu_pd(p + 10), 1);
    const __m256d x = _mm256_shuffle_pd(a, b, 0b1010);
    const __m256d y = _mm256_shuffle_pd(a, c, 0b0101);
    const __m256d z = _mm256_shuffle_pd(b, c, 0b1010);
    // x - x is 0 exactly when x is finite.
    finite = _mm256_and_pd(
        finite, _mm256_and_pd(_mm256_cmp_pd(_mm256_sub_pd(x, x), zero, _CMP_EQ_OQ),
                              _mm256_and_pd(_mm256_cmp_pd(_mm256_sub_pd(y, y), zero, _CMP_EQ_OQ),
                                            _mm256_cmp_pd(_mm256_sub_pd(z, z), zero, _CMP_EQ_OQ))));
    const __m256d cx = view_row_avx2(m00, m10, m20, m30, x, y, z);
    const __m256d cy = view_row_avx2(m01, m11, m21, m31, x, y, z);
    const __m256d d = _mm256_xor_pd(view_row_avx2(m02, m12, m22, m32, x, y, z), sign);
    const auto front = uint32_t(_mm256_movemask_pd(_mm256_cmp_pd(d, near, _CMP_GT_OQ)));
    const __m256d inv_d = kOrthographic ? one : _mm256_div_pd(one, d);
    const __m256d x_ndc = kOrthographic ? _mm256_add_pd(_mm256_mul_pd(sx, cx), tx)
                                        : _mm256_mul_pd(_mm256_mul_pd(sx, cx), inv_d);
    const __m256d y_ndc = kOrthographic ? _mm256_add_pd(_mm256_mul_pd(sy, cy), ty)
                                        : _mm256_mul_pd(_mm256_mul_pd(sy, cy), inv_d);
    _mm256_storeu_pd(px + k, _mm256_mul_pd(_mm256_mul_pd(half, _mm256_add_pd(x_ndc, one)), w));
    _mm256_storeu_pd(py + k, _mm256_mul_pd(_mm256_mul_pd(half, _mm256_sub_pd(one, y_ndc)), h));
    const __m256d s = _mm256_mul_pd(_mm256_mul_pd(r3, ppu), inv_d);
    _mm256_storeu_pd(sigma2 + k, _mm256_add_pd(_mm256_mul_pd(s, s), quarter));
    // Bit j of `front` to byte j (the four products land on distinct bits, no carries).
    const uint32_t bytes = (front * 0x204081u) & 0x01010101u;
    std::memcpy(in_front + k, &bytes, 4);
  }
  return _mm256_movemask_pd(finite) == 0xf;
}
#endif

}  // namespace

bool DensitySplatter::project_xyz(const unsigned char *xyz, double radius, int count,
                                  DensityFootprints *out) const {
#ifdef LANTERN_DENSITY_X86
  const bool avx2 = cpu_has_avx2(), avx512 = cpu_has_avx512_bw();
  if (!avx2 || count % 8 != 0) return false;
  out->resize(size_t(count));
  if (!avx512)
    return g_.orthographic ? project_xyz_avx2<true>(g_, xyz, radius, count, out)
                           : project_xyz_avx2<false>(g_, xyz, radius, count, out);
  return g_.orthographic ? project_xyz_avx512<true>(g_, xyz, radius, count, out)
                         : project_xyz_avx512<false>(g_, xyz, radius, count, out);
#else
  (void)xyz, (void)radius, (void)count, (void)out;
  return false;
#endif
}

void DensityImage::compact() {
  if (pitch == width) return;
  const size_t row = size_t(width) * size_t(channels), from = size_t(pitch) * size_t(channels);
  // Row y moves down to y row: never past where a later row is still to be read.
  for (size_t y = 1; y < size_t(height); ++y)
    std::memmove(sum.data() + y * row, sum.data() + y * from, row * sizeof(int64_t));
  sum.resize(row * size_t(height));
  pitch = width;
}

DensitySplatter::DensitySplatter(const ViewGeometry &g, DensityImage *image)
    : g_(g), image_(image), table_(DensityKernelTable::get()) {
  set_pixel_loop(DensityPixelLoop::kAuto);
}

void DensitySplatter::set_pixel_loop(DensityPixelLoop loop) {
  add4_ = add4_scalar;
  units_ = units_avx2_ = false;
#ifdef LANTERN_DENSITY_X86
  const bool avx2 = cpu_has_avx2(), avx512 = cpu_has_avx512_bw();
  if (loop == DensityPixelLoop::kScalar) return;
  add4_ = add4_sse2;
  if (loop == DensityPixelLoop::kSse2 || !avx2) return;
  add4_ = add4_avx2;
  units_avx2_ = true;
  if (loop == DensityPixelLoop::kAvx2 || !avx512) return;
  add4_ = add4_avx512;
  units_avx2_ = false;
  units_ = loop == DensityPixelLoop::kAuto;
#else
  (void)loop;
#endif
}

void DensitySplatter::project_all(const double *x, const double *y, const double *z,
                                  const double *r, double radius, double scale, int count,
                                  DensityFootprints *out) const {
  out->resize(size_t(count));
#ifdef LANTERN_DENSITY_X86
  const bool avx2 = cpu_has_avx2();
  if (avx2) return project_avx2(g_, x, y, z, r, radius, scale, count, out);
#endif
  project_portable(g_, x, y, z, r, radius, scale, count, out);
}

bool DensitySplatter::project(const glm::dvec3 &c, double r, DensityFootprint *out) const {
  const double d = -c.z;
  if (!(d > g_.near_plane)) return false;
  // One division per particle (perspective), not three.
  const double inv_d = g_.orthographic ? 1.0 : 1.0 / d;
  const double x_ndc = g_.orthographic ? g_.sx * c.x + g_.tx : g_.sx * c.x * inv_d;
  const double y_ndc = g_.orthographic ? g_.sy * c.y + g_.ty : g_.sy * c.y * inv_d;
  out->px = 0.5 * (x_ndc + 1.0) * g_.width;
  out->py = 0.5 * (1.0 - y_ndc) * g_.height;
  const double s = r / kCutoffSigmas * (0.5 * g_.height * g_.sy) * inv_d;  // pixels_per_unit(d)
  // The table is indexed by sigma^2: no square root on the common path (its latency was 14 % of
  // the splat's own samples on fcc 1 M).
  out->sigma2 = s * s + kPixelFilterSigma * kPixelFilterSigma;
  return true;
}

bool DensitySplatter::splat(const glm::dvec3 &c, double r, double weight, const Rgb8 &color) {
  DensityFootprint f;
  return project(c, r, &f) && deposit(f, weight, color);
}

// W = weight 2^F in [2^23, 2^24): F = 23 - floor(log2 weight). Weights repeat (1, or n / keep
// for a whole brick), so the factors are kept from the previous particle when they can be.
void DensitySplatter::set_factors(double weight, const Rgb8 &color) {
  // The colour packed in one word: comparing the arrays costs a library call.
  const uint32_t packed = uint32_t(color[0]) | uint32_t(color[1]) << 8 | uint32_t(color[2]) << 16;
  if (weight == last_weight_ && packed == last_color_) return;
  const int f = kWeightMantissaBits - 1 - std::ilogb(weight);
  // Rounded, but kept below 2^24 so that W 256 < 2^32.
  const uint64_t w = std::min(uint64_t(std::ldexp(weight, f) + 0.5), (uint64_t(1) << 24) - 1);
  factors_m_[0] = w << 8;
  for (int k3 = 0; k3 < 3; ++k3) factors_m_[1 + k3] = w * color[size_t(k3)];
  factors_shift_ = f + 2 * kDensityTapBits + 8 - kDensityFractionBits;
  last_weight_ = weight, last_color_ = packed;
}

bool DensitySplatter::bin(const DensityFootprint &fp, const Rgb8 &color, DensityBins *bins) {
  const int k = table_.index_of_variance(fp.sigma2);
  if (k >= kDensitySigmaCount) return deposit(fp, 1.0, color);  // wide: no table entry
  constexpr double kFar = double(1 << 30);                      // as deposit()
  if (!(std::abs(fp.px) < kFar && std::abs(fp.py) < kFar)) return false;
  AxisTaps ax, ay;
  if (!table_.taps(fp.px, k, g_.width, &ax) || !table_.taps(fp.py, k, g_.height, &ay)) return false;
  DensityRecord r;
  r.taps_x = uint32_t(ax.taps - table_.tap_data()),
  r.taps_y = uint32_t(ay.taps - table_.tap_data());
  r.first_x = int16_t(ax.first), r.first_y = int16_t(ay.first);
  r.count_x = uint8_t(ax.count), r.count_y = uint8_t(ay.count);
  std::copy(color.begin(), color.end(), r.color);
  file(r, bins);
  return true;
}

namespace {

// Whether a batch's table footprints follow each other on the image: of the footprints k = 4,
// 8, 12, ... whose predecessor k - 1 is on the image too, at least 7 in 8 start within 16 px of
// it (a published order that is spatially coherent, as a lattice's or a cell-sorted one's).
// Their pixels are then in cache from the footprints before, and filing them in tile bins only
// to read them back costs more than it saves (fcc 10 M at 1024^2: about 10 % of the pass). One
// pair in four decides as well as every pair and costs a quarter (the decision moves no sum:
// both ways deposit the same integers).
bool coherent_on_image(const DensityPlacements &p, const uint8_t *in_front, int count) {
  constexpr int kNear = 16;
  const auto on = [&](size_t at) {
    return in_front[at] && p.k[at] < kDensitySigmaCount && p.count_x[at] != 0;
  };
  int64_t near = 0, total = 0;
  for (int i = 4; i < count; i += 4) {
    const auto at = size_t(i);
    if (!on(at) || !on(at - 1)) continue;
    ++total;
    near += std::abs(p.first_x[at] - p.first_x[at - 1]) <= kNear &&
            std::abs(p.first_y[at] - p.first_y[at - 1]) <= kNear;
  }
  return near * 8 >= total * 7;
}

}  // namespace

int64_t DensitySplatter::bin_all(const DensityFootprints &footprints, const Rgb8 *color, int count,
                                 DensityBins *bins) {
  table_.place_all(footprints.px.data(), footprints.py.data(), footprints.sigma2.data(), count,
                   g_.width, g_.height, &placements_);
  const DensityPlacements &p = placements_;
  const DensityStreamAhead ahead = ahead_;
  ahead_ = {};
  const bool direct = coherent_on_image(p, footprints.in_front.data(), count);
  const uint16_t *taps = table_.tap_data();
  int64_t touched = 0;
  // Coherent with four channels: the weight-1 loop first, then the rest below.
  const bool units = direct && (units_ || units_avx2_) && image_->channels == 4;
#ifdef LANTERN_DENSITY_X86
  if (units) {
    int64_t rest = 0;
    touched += (units_ ? add_units_placed : add_units_placed_avx2)(
        image_->sum.data(), image_->pitch, taps, p, footprints.in_front.data(), color, count,
        &pixels_written_, &rest, ahead);
    if (rest == 0) return touched;  // nothing left for the loop below
  }
#endif
  for (int i = 0; i < count; ++i) {
    const auto at = size_t(i);
    if (!footprints.in_front[at]) continue;
    if (p.k[at] >= kDensitySigmaCount) {  // wide: no table entry
      touched +=
          deposit({footprints.px[at], footprints.py[at], footprints.sigma2[at]}, 1.0, color[i]);
      continue;
    }
    if (p.count_x[at] == 0 || (units && p.count_x[at] <= kUnitMaxWidth)) continue;
    ++touched;
    if (direct) {
      add({taps + p.taps_x[at], p.first_x[at], p.count_x[at]},
          {taps + p.taps_y[at], p.first_y[at], p.count_y[at]}, 1.0, color[i]);
      continue;
    }
    DensityRecord r;
    r.taps_x = p.taps_x[at], r.taps_y = p.taps_y[at];
    r.first_x = int16_t(p.first_x[at]), r.first_y = int16_t(p.first_y[at]);
    r.count_x = uint8_t(p.count_x[at]), r.count_y = uint8_t(p.count_y[at]);
    std::copy(color[i].begin(), color[i].end(), r.color);
    file(r, bins);
  }
  return touched;
}

void DensitySplatter::add(const AxisTaps &ax, const AxisTaps &ay, double weight,
                          const Rgb8 &color) {
  pixels_written_ += int64_t(ax.count) * ay.count;
  set_factors(weight, color);
  if (image_->channels == 4)
    add4_(image_->sum.data(), image_->pitch, ax, ay, factors_m_, factors_shift_);
  else
    add_scalar(
        image_->sum.data(), image_->pitch, image_->channels, ax, ay,
        Factors{{factors_m_[0], factors_m_[1], factors_m_[2], factors_m_[3]}, factors_shift_});
}

void DensitySplatter::deposit_bins(const DensityBins &bins) {
  const uint16_t *taps = table_.tap_data();
  const bool units = units_ && image_->channels == 4;
  for (const std::vector<DensityRecord> &tile : bins.tiles) {
#ifdef LANTERN_DENSITY_X86
    if (units) add_units_binned(image_->sum.data(), image_->pitch, taps, tile, &pixels_written_);
#endif
    for (const DensityRecord &r : tile)
      if (!units || r.count_x > kUnitMaxWidth)
        add({taps + r.taps_x, r.first_x, r.count_x}, {taps + r.taps_y, r.first_y, r.count_y}, 1.0,
            {r.color[0], r.color[1], r.color[2]});
  }
}

int64_t DensitySplatter::deposit_all(const DensityFootprints &footprints, const uint8_t *skip,
                                     const Rgb8 *color, int count, double weight) {
  int64_t touched = 0;
  for (int k = 0; k < count; ++k)
    if (footprints.in_front[size_t(k)] && !skip[k])
      touched += deposit(
          {footprints.px[size_t(k)], footprints.py[size_t(k)], footprints.sigma2[size_t(k)]},
          weight, color[k]);
  return touched;
}

bool DensitySplatter::deposit(const DensityFootprint &fp, double weight, const Rgb8 &color) {
  if (!(weight >= kDensityMinWeight && weight < kDensityMaxWeight)) return false;
  const double px = fp.px, py = fp.py, sigma2 = fp.sigma2;
  AxisTaps ax, ay;
  const int k = table_.index_of_variance(sigma2);
  if (k < kDensitySigmaCount) {
    // Table footprints reach 25 px at most: a centre 2^30 px away touches nothing (and this keeps
    // the int conversions in range; also false for a non-finite centre).
    constexpr double kFar = double(1 << 30);
    if (!(std::abs(px) < kFar && std::abs(py) < kFar)) return false;
    if (!table_.taps(px, k, g_.width, &ax) || !table_.taps(py, k, g_.height, &ay)) return false;
  } else {
    const double sigma = std::sqrt(sigma2);
    if (!(std::isfinite(px) && std::isfinite(py))) return false;
    if (!density_computed_taps(px, sigma, g_.width, &scratch_x_, &ax) ||
        !density_computed_taps(py, sigma, g_.height, &scratch_y_, &ay))
      return false;
  }
  add(ax, ay, weight, color);
  return true;
}

}  // namespace lantern
