#include "core/finish/screen_ambient_occlusion.h"

// No fused multiply-adds: the AVX-512 and AVX2 compilations of the half-resolution pass must round
// every operation as the baseline compilation (which has none) does, or the images would depend on
// the processor (GCC contracts a * b + c wherever the target has FMA, and AVX-512 implies it).
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/common/cpu_features.h"
#include "core/common/rank_threads.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

// The vector helpers below are always inlined: no vector crosses a call, so the ABI note GCC
// gives for 32-byte vectors in baseline code does not apply.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace lantern {

namespace {

constexpr float kGoldenAngle = 2.39996323f;  // radians: pi (3 - sqrt 5)
// Added before truncating a sample offset (|offset| <= kMaxAoPixels) to round it to nearest.
constexpr float kRoundShift = float(kMaxAoPixels + 1) + 0.5f;
constexpr float kBackground = ViewPositions::kBackground;
static_assert(ViewPositions::kBorder >= kMaxAoPixels, "samples read the border unchecked");

glm::vec3 position(const ViewPositions &v, int x, int y, float z) {
  return {v.view_x(x, z), v.view_y(y, z), -z};
}

// The tangent along one axis at (x, y): towards the neighbour whose depth differs less, or a
// zero vector where both neighbours are background or outside the held rows.
glm::vec3 tangent(const ViewPositions &v, int x, int y, const glm::vec3 &p, int dx, int dy) {
  glm::vec3 best(0.0f);
  float best_step = kBackground;
  for (const int s : {1, -1}) {
    const int nx = x + s * dx, ny = y + s * dy;
    if (nx < 0 || nx >= v.width() || ny < v.first_row() || ny >= v.last_row()) continue;
    const float z = v.z(nx, ny);
    if (z == kBackground) continue;
    const float step = std::abs(z - (-p.z));
    if (step < best_step) {
      best_step = step;
      best = float(s) * (position(v, nx, ny, z) - p);
    }
  }
  return best;
}

// The surface normal at (x, y), facing the eye; the direction to the eye where it cannot be
// reconstructed.
glm::vec3 normal_at(const ViewPositions &v, int x, int y, const glm::vec3 &p) {
  const glm::vec3 to_eye = glm::normalize(-p);
  const glm::vec3 n = glm::cross(tangent(v, x, y, p, 1, 0), tangent(v, x, y, p, 0, 1));
  const float length = glm::length(n);
  if (!(length > 0.0f)) return to_eye;
  return glm::dot(n, to_eye) < 0.0f ? -n / length : n / length;
}

// The spiral's unit-disc offsets, turned for each of the 16 pixel positions mod 4.
std::vector<float> sample_kernel(int samples) {
  std::vector<float> kernel(size_t(16) * size_t(samples) * 2);
  for (int r = 0; r < 16; ++r) {
    const float turn = float(r) * (2.0f * 3.14159265f / 16.0f);
    for (int k = 0; k < samples; ++k) {
      const float a = float(k) * kGoldenAngle + turn;
      const float d = std::sqrt((float(k) + 0.5f) / float(samples));
      kernel[(size_t(r) * size_t(samples) + size_t(k)) * 2] = d * std::cos(a);
      kernel[(size_t(r) * size_t(samples) + size_t(k)) * 2 + 1] = d * std::sin(a);
    }
  }
  return kernel;
}

// A fixed shuffle of the 16 turns over a 4 x 4 block, so neighbouring pixels differ most.
constexpr int kTurnOf[16] = {0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5};

// The summed occlusion of the `n` samples at drawn pixel (x, y) at distance z, with the turn of
// (x mod 4, y mod 4); negative where the radius covers less than a pixel (no occlusion).
float occlusion_at(const ViewPositions &v, const std::vector<float> &kernel, int n, float radius,
                   int x, int y, float z) {
  const int w = v.width(), h = v.height();
  const float r2 = radius * radius;
  const float pixels = std::min(float(kMaxAoPixels), radius * v.pixels_per_unit(z));
  if (pixels < 1.0f) return -1.0f;  // the whole kernel would read this pixel
  const glm::vec3 p = position(v, x, y, z);
  const glm::vec3 normal = normal_at(v, x, y, p);
  const float *k = &kernel[size_t(kTurnOf[(y & 3) * 4 + (x & 3)]) * size_t(n) * 2];
  float occlusion = 0.0f;
  for (int s = 0; s < n; ++s) {
    // Offsets rounded to nearest (half up) by truncating a positive value: no libm call.
    const int sx = x + int(pixels * k[2 * s] + kRoundShift) - kMaxAoPixels - 1;
    const int sy = y + int(pixels * k[2 * s + 1] + kRoundShift) - kMaxAoPixels - 1;
    if (sx < 0 || sx >= w || sy < 0 || sy >= h) continue;
    const float sz = v.z(sx, sy);
    if (sz == kBackground) continue;
    const glm::vec3 d = position(v, sx, sy, sz) - p;
    const float d2 = glm::dot(d, d);
    if (!(d2 > 0.0f) || d2 >= r2) continue;
    const float cosine = glm::dot(normal, d) / std::sqrt(d2);
    occlusion += std::max(0.0f, cosine - kAoBias) * (1.0f - d2 / r2);
  }
  return occlusion;
}

void darken(uint8_t *rgba, float keep) {
  for (int c = 0; c < 3; ++c) rgba[c] = uint8_t(float(rgba[c]) * keep + 0.5f);
}

void full_resolution_rows(const ViewPositions &v, const AmbientOcclusionStyle &style,
                          const std::vector<float> &kernel, BandFrame *band, int y_begin,
                          int y_end) {
  const int w = v.width(), n = style.samples;
  const float gain = 2.0f * style.strength / float(n);
  for (int y = y_begin; y < y_end; ++y) {
    uint8_t *rgba = &band->frame.rgba[size_t(y - band->first) * size_t(w) * 4];
    for (int x = 0; x < w; ++x) {
      const float z = v.z(x, y);
      if (z == kBackground) continue;
      const float occlusion = occlusion_at(v, kernel, n, style.radius, x, y, z);
      if (occlusion < 0.0f) continue;
      darken(rgba + 4 * x, 1.0f - std::min(style.strength, gain * occlusion));
    }
  }
}

// Every owned row on its own: `threads` parts of them at once give the same bytes.
void full_resolution(const ViewPositions &v, const AmbientOcclusionStyle &style, BandFrame *band,
                     int threads) {
  const std::vector<float> kernel = sample_kernel(style.samples);
  const int y0 = band->owned.y0, rows = std::max(0, band->owned.y1 - y0);
  run_in_parts(parts_for(threads, rows, 4), rows, [&](int, int64_t a, int64_t b) {
    full_resolution_rows(v, style, kernel, band, y0 + int(a), y0 + int(b));
  });
}

// ---- Half resolution -------------------------------------------------------------------------
//
// The estimates sit at the pixels (2 i, 2 j): column i of estimate row j. Vectors of 8 lanes
// (GCC vector extensions) hold 8 estimates or 8 pixels of a row. The whole pass is compiled
// twice, for AVX2 and for the baseline instruction set (where a vector is two SSE registers),
// from the same code: the same IEEE operations in the same order in every lane, so the same bits.

using F8 = float __attribute__((vector_size(32)));
using I8 = int32_t __attribute__((vector_size(32)));
constexpr int kLanes = 8;
// The blur's reach in estimates on each side, and its weights 1 2 2 2 1: any 5 neighbours of a
// row or column cover the 4 turns of that axis with equal weight (the two ends share one).
constexpr int kBlurReach = 2;
constexpr float kBlurWeight[2 * kBlurReach + 1] = {1.0f, 2.0f, 2.0f, 2.0f, 1.0f};
// A pixel none of whose 1, 2 or 4 nearest estimates lies at its depth takes the nearest in depth
// of the 4 x 4 around: estimate columns (and rows) i - kSearchBehind .. i + kSearchAhead.
constexpr int kSearchBehind = 1, kSearchAhead = 2;
// Estimates of padding on each side of a row: a vector of 8 read kBlurReach beyond the last
// column stays inside the row.
constexpr int kPad = 16;

#define LANTERN_AO_INLINE inline __attribute__((always_inline))
// The few AVX2 instructions below written as inline assembly (GCC). Clang checks an asm operand's
// size against the function the asm is written in, and these helpers are compiled for the
// baseline, so it refuses their 256-bit operands (the fuzzing build, tests/fuzz/run_fuzzers.sh,
// stopped there): under clang the generic forms beside them run instead, with the same bits.
#if defined(__x86_64__) && !defined(__clang__)
#define LANTERN_AO_AVX2_ASM 1
#endif

LANTERN_AO_INLINE F8 load8(const float *p) {
  F8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
LANTERN_AO_INLINE void store8(float *p, F8 v) {
  std::memcpy(p, &v, sizeof v);
}
LANTERN_AO_INLINE F8 splat(float a) {
  return F8{} + a;
}
LANTERN_AO_INLINE I8 splat_int(int32_t a) {
  return I8{} + a;
}
LANTERN_AO_INLINE F8 select(I8 mask, F8 yes, F8 no) {
  return mask ? yes : no;
}
LANTERN_AO_INLINE F8 min8(F8 a, F8 b) {
  return a < b ? a : b;
}
LANTERN_AO_INLINE F8 max8(F8 a, F8 b) {
  return a > b ? a : b;
}
// |a| with the sign bit cleared: one AND, where the compare-and-select form took a compare, a
// negation and a blend in every tap of the blurs and the upsampling. Its readers only compare it,
// for which the two agree (-0 and +0 compare equal, NaN is NaN either way).
LANTERN_AO_INLINE F8 abs8(F8 a) {
  I8 bits;
  std::memcpy(&bits, &a, sizeof bits);
  bits &= 0x7fffffff;
  std::memcpy(&a, &bits, sizeof a);
  return a;
}
LANTERN_AO_INLINE bool any(I8 mask) {
#if defined(__x86_64__)
  // One SSE2 movemask of the two halves or-ed (baseline, so valid in every compilation): the
  // lane-by-lane loop compiled to eight extractions.
  using I4 = int32_t __attribute__((vector_size(16)));
  const I4 either = __builtin_shufflevector(mask, mask, 0, 1, 2, 3) |
                    __builtin_shufflevector(mask, mask, 4, 5, 6, 7);
  return _mm_movemask_ps(_mm_castsi128_ps(__m128i(either))) != 0;
#else
  bool yes = false;
  for (int l = 0; l < kLanes; ++l) yes = yes || mask[l] != 0;
  return yes;
#endif
}
// The instructions a compilation of the pass may use beyond the baseline (see
// half_resolution_pass). Those few are written as inline assembly: GCC does not inline an
// intrinsic's target-specific body into these always-inline helpers, which are not themselves
// compiled for a target, and a call per sample would cost more than the instruction.
struct Baseline {
  static constexpr bool kAvx2 = false, kGather = false;
};
// AVX2 (or AVX-512), reading the distances lane by lane.
struct Avx2Loads {
  static constexpr bool kAvx2 = true, kGather = false;
};
// AVX2 with vgatherdps: faster than 8 loads on some processors (cpu_prefers_gathers()).
struct Avx2Gather {
  static constexpr bool kAvx2 = true, kGather = true;
};

// Correctly rounded square roots (IEEE), so every path gives the same bits: one vsqrtps of 8 lanes
// with AVX2, else two SSE sqrtps (baseline): a scalar sqrtf may also set errno, which keeps the
// compiler from vectorising it.
template <class Isa>
LANTERN_AO_INLINE F8 sqrt8(F8 a) {
#if defined(__x86_64__)
#if defined(LANTERN_AO_AVX2_ASM)
  if constexpr (Isa::kAvx2) {
    F8 r;
    asm("vsqrtps %[a], %[r]" : [r] "=x"(r) : [a] "x"(a));
    return r;
  }
#endif
  using F4 = float __attribute__((vector_size(16)));
  const F4 low = __builtin_shufflevector(a, a, 0, 1, 2, 3);
  const F4 high = __builtin_shufflevector(a, a, 4, 5, 6, 7);
  const F4 low_root = F4(_mm_sqrt_ps(__m128(low))), high_root = F4(_mm_sqrt_ps(__m128(high)));
  return __builtin_shufflevector(low_root, high_root, 0, 1, 2, 3, 4, 5, 6, 7);
#else
  F8 r;
  for (int l = 0; l < kLanes; ++l) r[l] = std::sqrt(a[l]);
  return r;
#endif
}
// base[index] in each lane: one vgatherdps (8 loads in fewer instructions than 8 scalar loads and
// inserts) or lane by lane. Every index must be readable.
template <class Isa>
LANTERN_AO_INLINE F8 gather(const float *base, I8 index) {
#if defined(LANTERN_AO_AVX2_ASM)
  if constexpr (Isa::kGather) {
    F8 r{};
    I8 mask;  // all ones: every lane loads; the gather clears it
    asm("vpcmpeqd %[m], %[m], %[m]\n\tvgatherdps %[m], (%[b],%[i],4), %[r]"
        : [r] "+&x"(r), [m] "=&x"(mask)
        : [b] "r"(base), [i] "x"(index), "m"(*(const float(*)[])base));
    return r;
  }
#endif
  F8 r;
  for (int l = 0; l < kLanes; ++l) r[l] = base[index[l]];
  return r;
}
// view_x = (x_scale (x + 0.5) + x_offset) at(z): at(z) = z in perspective, 1 in orthographic.
LANTERN_AO_INLINE F8 at(bool orthographic, F8 z) {
  return orthographic ? splat(1.0f) : z;
}

// What every estimate reads.
struct Estimator {
  ViewPositions::Terms t;
  const float *z;  // the band's distances, held row `first` first, rows `stride` apart
  int stride, first;
  int samples;
  float radius, r2;
};

struct Vec3 {
  F8 x, y, z;
};

// A lane's view-space point at pixel (x, y) and distance z.
LANTERN_AO_INLINE Vec3 point8(const Estimator &e, F8 fx, F8 fy, F8 z) {
  const F8 a = at(e.t.orthographic, z);
  return {(splat(e.t.x_scale) * fx + e.t.x_offset) * a,
          (splat(e.t.y_scale) * fy + e.t.y_offset) * a, -z};
}

// One axis's tangent at P (distance z): towards the neighbour (+1 first, then -1) whose depth
// differs less, zero where neither is drawn; as tangent() does.
LANTERN_AO_INLINE Vec3 tangent8(const Vec3 &p, F8 z, const Vec3 &q_plus, F8 z_plus,
                                const Vec3 &q_minus, F8 z_minus) {
  const F8 step_plus = abs8(z_plus - z), step_minus = abs8(z_minus - z);
  const I8 plus = z_plus != kBackground;
  const I8 minus =
      (z_minus != kBackground) & (step_minus < select(plus, step_plus, splat(kBackground)));
  const F8 zero = splat(0.0f);
  return {select(minus, p.x - q_minus.x, select(plus, q_plus.x - p.x, zero)),
          select(minus, p.y - q_minus.y, select(plus, q_plus.y - p.y, zero)),
          select(minus, p.z - q_minus.z, select(plus, q_plus.z - p.z, zero))};
}

// oy * stride in each lane, for 0 <= oy < 2^15. kNarrow (stride < 2^15 too): one vpmaddwd (the
// lanes' high halves are zero) where pmulld takes two micro-operations and ten cycles on recent
// Intel cores; else, and in the baseline compilation, a plain multiply.
template <class Isa, bool kNarrow>
LANTERN_AO_INLINE I8 times_stride(I8 oy, I8 stride_pairs) {
#if defined(LANTERN_AO_AVX2_ASM)
  if constexpr (Isa::kAvx2 && kNarrow) {
    I8 r;
    asm("vpmaddwd %[b], %[a], %[r]" : [r] "=x"(r) : [a] "x"(oy), [b] "x"(stride_pairs));
    return r;
  }
#endif
  return oy * stride_pairs;
}

// max8(a, b), a > b ? a : b lane by lane, which is what vmaxps does (b where either is NaN): one
// instruction where GCC makes a compare and a blend of the generic form.
template <class Isa>
LANTERN_AO_INLINE F8 max_with(F8 a, F8 b) {
#if defined(LANTERN_AO_AVX2_ASM)
  if constexpr (Isa::kAvx2) {
    F8 r;
    asm("vmaxps %[b], %[a], %[r]" : [r] "=x"(r) : [a] "x"(a), [b] "x"(b));
    return r;
  }
#endif
  return max8(a, b);
}

// The sum of the samples' occlusion at 8 points p with normals n (estimate8). corner_x, corner_y:
// the pixel's x and y less kMaxAoPixels + 1, and corner their index in e.z; pixels: the spiral's
// radius in pixels, 0 in lanes whose estimate does not sample (which then read their own
// pixel, which never counts: d2 is 0 there, or NaN for the background). kOrthographic: the
// projection, fixed for the loop; kNarrow: e.stride < 2^15 (times_stride).
template <class Isa, bool kOrthographic, bool kNarrow>
LANTERN_AO_INLINE F8 summed_samples(const Estimator &e, I8 corner_x, I8 corner_y, I8 corner,
                                    F8 pixels, F8 z, const Vec3 &p, const Vec3 &n, const float *kx,
                                    const float *ky) {
  const F8 zero = splat(0.0f), inv_r2 = splat(1.0f / e.r2), r2 = splat(e.r2);
  const I8 stride = splat_int(e.stride);
  const F8 corner_centre_x = __builtin_convertvector(corner_x, F8) + 0.5f;
  const F8 corner_centre_y = __builtin_convertvector(corner_y, F8) + 0.5f;
  // The sample pixel and its distance of sample s; gathered one sample ahead of the arithmetic
  // that reads them, so that the gather's latency hides behind the sample before.
  struct Sample {
    I8 ox, oy;
    F8 sz;
  };
  const auto sample = [&](int s) {
    // Offsets in [0, 2 kMaxAoPixels + 2): the spiral's, plus kMaxAoPixels + 1, rounded to nearest
    // (half up) by truncating a positive value, as occlusion_at.
    const I8 ox = __builtin_convertvector(pixels * load8(kx + kLanes * s) + kRoundShift, I8);
    const I8 oy = __builtin_convertvector(pixels * load8(ky + kLanes * s) + kRoundShift, I8);
    // No bounds to test: a sample lies at most kMaxAoPixels from its pixel, so beyond the image
    // or the held rows it reads the positions' border, the background, which does not count.
    return Sample{ox, oy, gather<Isa>(e.z, corner + times_stride<Isa, kNarrow>(oy, stride) + ox)};
  };
  F8 occlusion = zero;
  Sample next = sample(0);
  for (int s = 0; s < e.samples; ++s) {
    const Sample here = next;
    if (s + 1 < e.samples) next = sample(s + 1);
    const F8 sz = here.sz, a = kOrthographic ? splat(1.0f) : sz;
    // The sample pixel's centre, float(corner + o) + 0.5 as corner_centre + float(o): small
    // integers and halves, so both are exact and the same.
    const F8 qx = (splat(e.t.x_scale) * (corner_centre_x + __builtin_convertvector(here.ox, F8)) +
                   e.t.x_offset) *
                  a;
    const F8 qy = (splat(e.t.y_scale) * (corner_centre_y + __builtin_convertvector(here.oy, F8)) +
                   e.t.y_offset) *
                  a;
    // q.z - p.z = -sz + z (p.z = -z), which is z - sz bit for bit.
    const F8 dx = qx - p.x, dy = qy - p.y, dz = z - sz;
    const F8 d2 = dx * dx + dy * dy + dz * dz;
    // A background sample (z = +infinity) has an infinite or NaN d2: it fails d2 < r2. Where a
    // sample does not count, the quotient may be anything: the mask drops it.
    const I8 counts = (d2 > 0.0f) & (d2 < r2);
    const F8 cosine = (n.x * dx + n.y * dy + n.z * dz) / sqrt8<Isa>(d2);
    const F8 term = max_with<Isa>(zero, cosine - kAoBias) * (1.0f - d2 * inv_r2);
    occlusion += select(counts, term, zero);
  }
  return occlusion;
}

// The summed occlusion of 8 pixels (x, y), x < width and y held: -1 where the pixel is
// background, 0 where the radius covers less than a pixel. kx, ky: the spiral's offsets of each
// lane's turn, sample s at [kLanes s + lane].
template <class Isa>
LANTERN_AO_INLINE F8 estimate8(const Estimator &e, I8 x, I8 y, const float *kx, const float *ky) {
  const F8 zero = splat(0.0f);
  const I8 row = (y - e.first) * e.stride;
  const I8 centre = row + x;
  const F8 z = gather<Isa>(e.z, centre);
  const I8 drawn = z != kBackground;
  const F8 ppu = e.t.orthographic ? splat(e.t.ppu) : splat(e.t.ppu) / z;
  const F8 pixels = min8(splat(float(kMaxAoPixels)), splat(e.radius) * ppu);
  const I8 active = drawn & (pixels >= 1.0f);
  if (!any(active)) return select(drawn, zero, splat(-1.0f));
  const F8 fx = __builtin_convertvector(x, F8) + 0.5f, fy = __builtin_convertvector(y, F8) + 0.5f;
  const Vec3 p = point8(e, fx, fy, z);
  // Neighbours outside the image or the held rows count as not drawn: x and y are the image's and
  // held, so those read the positions' border, the background.
  const F8 z_right = gather<Isa>(e.z, centre + 1), z_left = gather<Isa>(e.z, centre - 1);
  const F8 z_down = gather<Isa>(e.z, centre + e.stride), z_up = gather<Isa>(e.z, centre - e.stride);
  const Vec3 tx = tangent8(p, z, point8(e, fx + 1.0f, fy, z_right), z_right,
                           point8(e, fx - 1.0f, fy, z_left), z_left);
  const Vec3 ty = tangent8(p, z, point8(e, fx, fy + 1.0f, z_down), z_down,
                           point8(e, fx, fy - 1.0f, z_up), z_up);
  // n = tx x ty, facing the eye; the direction to the eye where it is degenerate.
  Vec3 n{tx.y * ty.z - tx.z * ty.y, tx.z * ty.x - tx.x * ty.z, tx.x * ty.y - tx.y * ty.x};
  const F8 eye = sqrt8<Isa>(p.x * p.x + p.y * p.y + p.z * p.z);
  const Vec3 to_eye{-p.x / eye, -p.y / eye, -p.z / eye};
  const F8 length = sqrt8<Isa>(n.x * n.x + n.y * n.y + n.z * n.z);
  const I8 has_normal = length > 0.0f;
  const F8 facing =
      select(n.x * to_eye.x + n.y * to_eye.y + n.z * to_eye.z < 0.0f, -length, length);
  n = {select(has_normal, n.x / facing, to_eye.x), select(has_normal, n.y / facing, to_eye.y),
       select(has_normal, n.z / facing, to_eye.z)};
  const I8 corner_x = x - (kMaxAoPixels + 1), corner_y = y - (kMaxAoPixels + 1);
  const I8 corner = centre - (kMaxAoPixels + 1) * (e.stride + 1);
  // Lanes that do not sample read their own pixel (zero offsets).
  const F8 radius = select(active, pixels, zero);
  const bool narrow = e.stride < (1 << 15);
  F8 occlusion;
  if (e.t.orthographic)
    occlusion = narrow ? summed_samples<Isa, true, true>(e, corner_x, corner_y, corner, radius, z,
                                                         p, n, kx, ky)
                       : summed_samples<Isa, true, false>(e, corner_x, corner_y, corner, radius, z,
                                                          p, n, kx, ky);
  else
    occlusion = narrow ? summed_samples<Isa, false, true>(e, corner_x, corner_y, corner, radius, z,
                                                          p, n, kx, ky)
                       : summed_samples<Isa, false, false>(e, corner_x, corner_y, corner, radius, z,
                                                           p, n, kx, ky);
  return select(drawn, occlusion, splat(-1.0f));
}

// A band's estimates: rows [j0, j1), columns padded by kPad each side; z = +inf where there is
// no estimate (background, padding, rows outside the image). In an AoScratch's vectors, kept
// from frame to frame and not filled again: a row's z is written whole (its padding cleared,
// clear_padding, or copied) or the row cleared (clear_row) before it is read, and a value is
// read only where its z is within the tolerance of a drawn pixel's, so where it was written.
// (Fresh grids every frame took about 0.2 ms of void_impact's 3.6 ms stage a rank, mostly
// faulting in their 3.4 MB; not filling fresh ones saved nothing.)
struct EstimateGrid {
  int columns = 0, stride = 0, j0 = 0, j1 = 0;
  std::vector<float> &value, &z;
  EstimateGrid(std::vector<float> &v, std::vector<float> &d) : value(v), z(d) {}
  void reset(int c, int a, int b) {
    columns = c, stride = c + 2 * kPad, j0 = a, j1 = b;
    value.resize(size_t(stride) * size_t(std::max(0, b - a)));
    z.resize(value.size());
  }
  float *value_at(int j) { return &value[size_t(j - j0) * size_t(stride) + kPad]; }
  float *z_at(int j) { return &z[size_t(j - j0) * size_t(stride) + kPad]; }
  void clear_padding(int j) {
    float *v = value_at(j), *d = z_at(j);
    std::fill(v - kPad, v, 0.0f);
    std::fill(v + columns, v + columns + kPad, 0.0f);
    std::fill(d - kPad, d, kBackground);
    std::fill(d + columns, d + columns + kPad, kBackground);
  }
  void clear_row(int j) {
    std::fill(value_at(j) - kPad, value_at(j) + columns + kPad, 0.0f);
    std::fill(z_at(j) - kPad, z_at(j) + columns + kPad, kBackground);
  }
};

// One depth-aware 1 2 2 2 1 blur of 8 estimates: taps at value[k * step], z[k * step] for
// k = -2..2, kept where within `tolerance` of the centre's depth.
LANTERN_AO_INLINE F8 blur8(const float *value, const float *z, ptrdiff_t step, F8 tolerance) {
  const F8 zc = load8(z), zero = splat(0.0f);
  F8 sum = zero, weight = zero;
  for (int k = -kBlurReach; k <= kBlurReach; ++k) {
    const I8 near = abs8(load8(z + k * step) - zc) <= tolerance;
    sum += select(near, kBlurWeight[k + kBlurReach] * load8(value + k * step), zero);
    weight += select(near, splat(kBlurWeight[k + kBlurReach]), zero);
  }
  return select(zc != kBackground, sum / weight, zero);
}

// Darkens 8 RGBA pixels by their factors (1: unchanged), as darken() does each.
LANTERN_AO_INLINE void darken8(uint8_t *rgba, F8 keep) {
  I8 packed;
  std::memcpy(&packed, rgba, sizeof packed);
  I8 out = packed & splat_int(int32_t(0xff000000u));
  for (int c = 0; c < 3; ++c) {
    const F8 channel = __builtin_convertvector((packed >> (8 * c)) & 0xff, F8);
    out |= __builtin_convertvector(channel * keep + 0.5f, I8) << (8 * c);
  }
  std::memcpy(rgba, &out, sizeof out);
}

struct Pixel {
  int32_t x, y;
};

// What the three phases of the half-resolution pass share: set up once per band, then each phase
// runs over contiguous parts of its rows (one part per thread, rank_threads.h). A phase writes
// only its own rows (estimate and blurred rows, or the owned image rows), and reads only what an
// earlier phase finished, so the bytes are the same for any number of parts.
struct HalfPass {
  const ViewPositions &v;
  const AmbientOcclusionStyle &style;
  BandFrame *band;
  int n = 0;          // samples
  float gain = 0.0f;  // 2 strength / n
  float tolerance = 0.0f;
  Estimator e;
  int columns = 0, rows = 0;
  int u0 = 0, u1 = 0, e0 = 0, e1 = 0;  // blurred and estimate rows (see half_resolution)
  std::vector<float> kernel;           // sample_kernel(n)
  std::vector<float> kx, ky;           // the spiral per estimate-row phase, lanes of column phases
  EstimateGrid raw, across, blurred;

  HalfPass(const ViewPositions &positions, const AmbientOcclusionStyle &s, BandFrame *b,
           AoScratch *scratch)
      : v(positions),
        style(s),
        band(b),
        n(s.samples),
        gain(2.0f * s.strength / float(s.samples)),
        tolerance(kAoDepthTolerance * s.radius),
        e{positions.terms(),
          positions.row(positions.first_row()),
          int(positions.stride()),
          positions.first_row(),
          s.samples,
          s.radius,
          s.radius * s.radius},
        columns((positions.width() + 1) / 2),
        rows((positions.height() + 1) / 2),
        // The blurred rows the owned rows read: [u0, u1), some possibly outside the image (none
        // held there); the estimate rows the blur reads: [e0, e1).
        u0(b->owned.y0 / 2 - kSearchBehind),
        u1((b->owned.y1 - 1) / 2 + kSearchAhead + 1),
        e0(std::max(0, u0 - kBlurReach)),
        e1(std::min(rows, u1 + kBlurReach)),
        kernel(sample_kernel(s.samples)),
        raw(scratch->raw_value, scratch->raw_z),
        across(scratch->across_value, scratch->across_z),
        blurred(scratch->blurred_value, scratch->blurred_z) {
    kx.resize(size_t(4) * size_t(n) * kLanes);
    ky.resize(kx.size());
    for (int phase = 0; phase < 4; ++phase)
      for (int sample = 0; sample < n; ++sample)
        for (int l = 0; l < kLanes; ++l) {
          const float *k = &kernel[size_t(kTurnOf[phase * 4 + (l & 3)]) * size_t(n) * 2];
          const size_t at = (size_t(phase) * size_t(n) + size_t(sample)) * kLanes + size_t(l);
          kx[at] = k[2 * sample];
          ky[at] = k[2 * sample + 1];
        }
    raw.reset(columns, e0, e1);
    across.reset(columns, e0, e1);
    blurred.reset(columns, u0, u1);
    // Blurred rows outside the image (at most kSearchAhead + 1 below it, kSearchBehind above)
    // hold no estimate.
    for (int j = u0; j < u1; ++j)
      if (j < 0 || j >= rows) blurred.clear_row(j);
  }
};

// Phase 1, estimate rows [j_begin, j_end) of [e0, e1): the raw estimates, and their blur along
// the row.
template <class Isa>
LANTERN_AO_INLINE void estimate_rows(HalfPass &pass, int j_begin, int j_end) {
  const ViewPositions &v = pass.v;
  const int w = v.width(), n = pass.n, columns = pass.columns;
  const F8 tolerance = splat(pass.tolerance);
  const I8 even_lanes = {0, 2, 4, 6, 8, 10, 12, 14};
  for (int j = j_begin; j < j_end; ++j) {
    pass.raw.clear_padding(j);  // across and blurred copy their rows' z, padding too, from raw's
    float *value = pass.raw.value_at(j), *z = pass.raw.z_at(j);
    const float *kxj = &pass.kx[size_t(j & 3) * size_t(n) * kLanes];
    const float *kyj = &pass.ky[size_t(j & 3) * size_t(n) * kLanes];
    for (int i0 = 0; i0 < columns; i0 += kLanes) {
      const I8 x = splat_int(2 * i0) + even_lanes;
      const I8 in_image = x < w;
      const F8 occlusion =
          estimate8<Isa>(pass.e, in_image ? x : splat_int(w - 1), splat_int(2 * j), kxj, kyj);
      const I8 held = in_image & (occlusion >= 0.0f);
      store8(value + i0, select(held, occlusion, splat(0.0f)));
      store8(z + i0, select(held, gather<Isa>(v.row(2 * j), in_image ? x : splat_int(0)),
                            splat(kBackground)));
    }
    // Lanes past the last column wrote into the padding: it must stay "no estimate".
    std::fill(z + columns, z + columns + kPad, kBackground);
    std::copy(z - kPad, z + columns + kPad, pass.across.z_at(j) - kPad);
    for (int i0 = 0; i0 < columns; i0 += kLanes)
      store8(pass.across.value_at(j) + i0, blur8(value + i0, z + i0, 1, tolerance));
  }
}

// Phase 2, blurred rows [j_begin, j_end) (within the image): the blur across the rows.
template <class Isa>
LANTERN_AO_INLINE void blur_rows(HalfPass &pass, int j_begin, int j_end) {
  const int columns = pass.columns;
  const F8 tolerance = splat(pass.tolerance);
  EstimateGrid &across = pass.across;
  for (int j = j_begin; j < j_end; ++j) {
    std::copy(across.z_at(j) - kPad, across.z_at(j) + columns + kPad, pass.blurred.z_at(j) - kPad);
    // Rows beyond the held estimates lie outside the image: their taps are not drawn.
    const float *z = across.z_at(j);
    for (int i0 = 0; i0 < columns; i0 += kLanes) {
      const F8 zc = load8(z + i0), zero = splat(0.0f);
      F8 sum = zero, weight = zero;
      for (int k = -kBlurReach; k <= kBlurReach; ++k) {
        if (j + k < pass.e0 || j + k >= pass.e1) continue;
        const I8 near = abs8(load8(across.z_at(j + k) + i0) - zc) <= tolerance;
        sum += select(near, kBlurWeight[k + kBlurReach] * load8(across.value_at(j + k) + i0), zero);
        weight += select(near, splat(kBlurWeight[k + kBlurReach]), zero);
      }
      store8(pass.blurred.value_at(j) + i0, select(zc != kBackground, sum / weight, zero));
    }
  }
}

// The lanes set in a mask, one bit each (bit l: lane l).
LANTERN_AO_INLINE unsigned lane_bits(I8 mask) {
#if defined(__x86_64__)
  using I4 = int32_t __attribute__((vector_size(16)));
  const auto low = __m128i(I4(__builtin_shufflevector(mask, mask, 0, 1, 2, 3)));
  const auto high = __m128i(I4(__builtin_shufflevector(mask, mask, 4, 5, 6, 7)));
  return unsigned(_mm_movemask_ps(_mm_castsi128_ps(low))) |
         unsigned(_mm_movemask_ps(_mm_castsi128_ps(high))) << 4;
#else
  unsigned bits = 0;
  for (int l = 0; l < kLanes; ++l) bits |= unsigned(mask[l] != 0) << l;
  return bits;
#endif
}

// A lone pixel's estimate (at distance z, in estimate column i of blurred row j): the nearest in
// depth of the 4 x 4 estimates around, if one is within `tolerance`; the first of equals in the
// order of rows, then columns. False where none is. One candidate at a time: the baseline
// compilation's search, and the reference the tests compare nearest_of_sixteen with.
LANTERN_AO_INLINE bool nearest_one_at_a_time(EstimateGrid &blurred, int j, int i, float z,
                                             float tolerance, float *value) {
  float nearest = tolerance;
  bool found = false;
  for (int b = -kSearchBehind; b <= kSearchAhead; ++b)
    for (int a = -kSearchBehind; a <= kSearchAhead; ++a) {
      const float step = std::abs(blurred.z_at(j + b)[i + a] - z);
      if (!(step <= nearest) || (found && step == nearest)) continue;
      nearest = step, *value = blurred.value_at(j + b)[i + a], found = true;
    }
  return found;
}

#if defined(__x86_64__)
// The same choice in four SSE vectors, one per estimate row: their minimum step, then the first
// candidate equal to it, with no branch per candidate, which the search one at a time mispredicted
// at every silhouette. Measured on void_impact at 1024^2 on 2 ranks, where 1-2 % of the pixels are
// lone: the lone pixels cost a rank 0.22-0.31 ms of the upsampling's 0.7-0.87 with that search,
// 0.16-0.23 ms of 0.64-0.73 with this one (their own estimates about 0.07 ms of either).
LANTERN_AO_INLINE bool nearest_of_sixteen(EstimateGrid &blurred, int j, int i, float z,
                                          float tolerance, float *value) {
  static_assert(kSearchBehind + kSearchAhead + 1 == 4, "four candidates to a row");
  const __m128 at = _mm_set1_ps(z), sign = _mm_set1_ps(-0.0f);
  const __m128 within = _mm_set1_ps(tolerance), none = _mm_set1_ps(kBackground);
  __m128 step[4];
  for (int r = 0; r < 4; ++r) {
    const __m128 depths = _mm_loadu_ps(blurred.z_at(j - kSearchBehind + r) + i - kSearchBehind);
    // |depth - z| (the sign bit cleared, as std::abs does); beyond the tolerance, or NaN, none.
    const __m128 s = _mm_andnot_ps(sign, _mm_sub_ps(depths, at));
    const __m128 near = _mm_cmple_ps(s, within);
    step[r] = _mm_or_ps(_mm_and_ps(near, s), _mm_andnot_ps(near, none));
  }
  __m128 least = _mm_min_ps(_mm_min_ps(step[0], step[1]), _mm_min_ps(step[2], step[3]));
  least = _mm_min_ps(least, _mm_shuffle_ps(least, least, _MM_SHUFFLE(1, 0, 3, 2)));
  least = _mm_min_ps(least, _mm_shuffle_ps(least, least, _MM_SHUFFLE(2, 3, 0, 1)));
  if (!(_mm_cvtss_f32(least) < kBackground)) return false;
  unsigned equal = 0;
  for (int r = 0; r < 4; ++r)
    equal |= unsigned(_mm_movemask_ps(_mm_cmpeq_ps(step[r], least))) << (4 * r);
  const int first = __builtin_ctz(equal);
  *value = blurred.value_at(j - kSearchBehind + first / 4)[i - kSearchBehind + first % 4];
  return true;
}
#endif

// The AVX2 and AVX-512 compilations search in vectors, the baseline one candidate at a time.
template <class Isa>
LANTERN_AO_INLINE bool nearest_estimate(EstimateGrid &blurred, int j, int i, float z,
                                        float tolerance, float *value) {
#if defined(__x86_64__)
  if constexpr (Isa::kAvx2) return nearest_of_sixteen(blurred, j, i, z, tolerance, value);
#endif
  return nearest_one_at_a_time(blurred, j, i, z, tolerance, value);
}

// Phase 3, owned image rows [y_begin, y_end): every pixel from the 1, 2 or 4 nearest estimates at
// its depth (each counted twice where it stands for both neighbours); those without one are
// estimated on their own at the end.
template <class Isa>
LANTERN_AO_INLINE void upsample_rows(HalfPass &pass, int y_begin, int y_end) {
  const ViewPositions &v = pass.v;
  const AmbientOcclusionStyle &style = pass.style;
  BandFrame *band = pass.band;
  EstimateGrid &blurred = pass.blurred;
  const int w = v.width(), n = pass.n;
  const float gain = pass.gain;
  const F8 tolerance = splat(pass.tolerance);
  std::vector<Pixel> alone;
  float zs[kLanes];
  uint8_t rgba8[4 * kLanes];
  for (int y = y_begin; y < y_end; ++y) {
    uint8_t *rgba = &band->frame.rgba[size_t(y - band->first) * size_t(w) * 4];
    const float *zrow = v.row(y);
    const int j = y / 2;
    const float *top_value = blurred.value_at(j), *top_z = blurred.z_at(j);
    const float *bottom_value = blurred.value_at(j + (y & 1)),
                *bottom_z = blurred.z_at(j + (y & 1));
    for (int x0 = 0; x0 < w; x0 += kLanes) {
      const int lanes = std::min(kLanes, w - x0);
      if (lanes < kLanes) {  // the row's last pixels: the lanes beyond it are background
        std::fill(zs, zs + kLanes, kBackground);
        std::copy(zrow + x0, zrow + x0 + lanes, zs);
      }
      const F8 z = load8(lanes < kLanes ? zs : zrow + x0);
      const I8 drawn = z != kBackground;
      if (!any(drawn)) continue;
      const int i0 = x0 / 2;
      F8 sum = splat(0.0f), count = splat(0.0f);
      for (const auto &[values, depths] :
           {std::pair{top_value, top_z}, std::pair{bottom_value, bottom_z}}) {
        const F8 a = load8(values + i0), za = load8(depths + i0);
        const F8 left = __builtin_shufflevector(a, a, 0, 0, 1, 1, 2, 2, 3, 3);
        const F8 right = __builtin_shufflevector(a, a, 0, 1, 1, 2, 2, 3, 3, 4);
        const F8 z_left = __builtin_shufflevector(za, za, 0, 0, 1, 1, 2, 2, 3, 3);
        const F8 z_right = __builtin_shufflevector(za, za, 0, 1, 1, 2, 2, 3, 3, 4);
        const I8 near_left = abs8(z_left - z) <= tolerance,
                 near_right = abs8(z_right - z) <= tolerance;
        sum += select(near_left, left, splat(0.0f));
        sum += select(near_right, right, splat(0.0f));
        count += select(near_left, splat(1.0f), splat(0.0f));
        count += select(near_right, splat(1.0f), splat(0.0f));
      }
      const I8 blended = drawn & (count > 0.0f);
      F8 keep =
          select(blended, 1.0f - min8(splat(style.strength), gain * (sum / count)), splat(1.0f));
      const I8 lone = drawn & ~blended;
      if (any(lone)) {
        // Each lone pixel's nearest estimate in depth among the 4 x 4 around (nearest_estimate),
        // else one of its own at the end.
        alignas(32) float lone_value[kLanes] = {};
        alignas(32) int32_t lone_found[kLanes] = {};
        const float *zl = lanes < kLanes ? zs : zrow + x0;
        for (unsigned bits = lane_bits(lone); bits != 0; bits &= bits - 1) {
          const int l = __builtin_ctz(bits);
          if (nearest_estimate<Isa>(blurred, j, (x0 + l) / 2, zl[l], tolerance[0], &lone_value[l]))
            lone_found[l] = -1;
          else
            alone.push_back({x0 + l, y});
        }
        I8 found;
        std::memcpy(&found, lone_found, sizeof found);
        keep = select(found, 1.0f - min8(splat(style.strength), gain * load8(lone_value)), keep);
      }
      if (lanes == kLanes) {
        darken8(rgba + 4 * x0, keep);
      } else {
        std::copy(rgba + 4 * x0, rgba + 4 * (x0 + lanes), rgba8);
        darken8(rgba8, keep);
        std::copy(rgba8, rgba8 + 4 * lanes, rgba + 4 * x0);
      }
    }
  }
  // The pixels without an estimate at their depth, 8 at a time with their own turns (each lane
  // on its own: which pixels share a vector does not change any). Their offsets' buffers only
  // where there are some: the pass may come here once a row.
  if (alone.empty()) return;
  std::vector<float> kx_alone(size_t(n) * kLanes), ky_alone(kx_alone.size());
  for (size_t a0 = 0; a0 < alone.size(); a0 += kLanes) {
    const int lanes = int(std::min<size_t>(kLanes, alone.size() - a0));
    I8 x, y;
    for (int l = 0; l < kLanes; ++l) {
      const Pixel &p = alone[a0 + size_t(std::min(l, lanes - 1))];
      x[l] = p.x, y[l] = p.y;
      const float *k = &pass.kernel[size_t(kTurnOf[(p.y & 3) * 4 + (p.x & 3)]) * size_t(n) * 2];
      for (int s = 0; s < n; ++s) {
        kx_alone[size_t(kLanes * s + l)] = k[2 * s];
        ky_alone[size_t(kLanes * s + l)] = k[2 * s + 1];
      }
    }
    const F8 occlusion = estimate8<Isa>(pass.e, x, y, kx_alone.data(), ky_alone.data());
    for (int l = 0; l < lanes; ++l) {
      if (!(occlusion[l] >= 0.0f)) continue;
      uint8_t *pixel =
          &band->frame.rgba[(size_t(y[l] - band->first) * size_t(w) + size_t(x[l])) * 4];
      darken(pixel, 1.0f - std::min(style.strength, gain * occlusion[l]));
    }
  }
}

// The phases compiled for one instruction set. The threads call these (from baseline code): a
// lambda inside a function compiled for a target is not itself compiled for it.
struct HalfPhases {
  void (*estimate)(HalfPass &, int, int);
  void (*blur)(HalfPass &, int, int);
  void (*upsample)(HalfPass &, int, int);
};

__attribute__((target("avx2"))) void estimate_avx2(HalfPass &p, int a, int b) {
  estimate_rows<Avx2Loads>(p, a, b);
}
__attribute__((target("avx2"))) void blur_avx2(HalfPass &p, int a, int b) {
  blur_rows<Avx2Loads>(p, a, b);
}
__attribute__((target("avx2"))) void upsample_avx2(HalfPass &p, int a, int b) {
  upsample_rows<Avx2Loads>(p, a, b);
}
__attribute__((target("avx2"))) void estimate_avx2_gather(HalfPass &p, int a, int b) {
  estimate_rows<Avx2Gather>(p, a, b);
}
__attribute__((target("avx2"))) void upsample_avx2_gather(HalfPass &p, int a, int b) {
  upsample_rows<Avx2Gather>(p, a, b);
}
// The same 8-lane code with AVX-512's 32 registers and mask registers.
#define LANTERN_AO_AVX512 __attribute__((target("avx512f,avx512vl,avx512dq,avx512bw")))
LANTERN_AO_AVX512 void estimate_avx512(HalfPass &p, int a, int b) {
  estimate_rows<Avx2Loads>(p, a, b);
}
LANTERN_AO_AVX512 void blur_avx512(HalfPass &p, int a, int b) {
  blur_rows<Avx2Loads>(p, a, b);
}
LANTERN_AO_AVX512 void upsample_avx512(HalfPass &p, int a, int b) {
  upsample_rows<Avx2Loads>(p, a, b);
}
#undef LANTERN_AO_AVX512
void estimate_portable(HalfPass &p, int a, int b) {
  estimate_rows<Baseline>(p, a, b);
}
void blur_portable(HalfPass &p, int a, int b) {
  blur_rows<Baseline>(p, a, b);
}
void upsample_portable(HalfPass &p, int a, int b) {
  upsample_rows<Baseline>(p, a, b);
}

// The fewest rows a thread takes in each phase: a thread costs tens of microseconds to start, a
// row of estimates a few.
constexpr int64_t kMinRowsPerPart = 16;

// The distances still to build, for the one-part pass: held rows [built, last_row) of
// *positions, from the band's depths.
struct RowsToBuild {
  ViewPositions *positions;
  const BandFrame *band;
  const Camera *camera;
  int built;

  // Builds every held row before y, on up to `threads` threads.
  void up_to(int y, int threads = 1) {
    y = std::min(y, positions->last_row());
    if (y <= built) return;
    positions->build_rows(*band, *camera, built, y, true, threads);
    built = y;
  }
};

// The three phases on one thread, row by row instead of phase by phase: each estimate row j just
// after the distances it reads are built, then every blurred row and every owned row whose inputs
// are done. So the distances are read while they are in the cache: built a few rows before the
// estimates reach them and upsampled a few rows after, where phase by phase each phase streamed
// the band's 2.4 MB of distances (at 1024^2 on 2 ranks) in from memory. The same rows computed
// from the same inputs: the same bytes as phase by phase. Measured at 1024^2 on 2 ranks of one
// thread, three rounds alternated with phase by phase: the screen AO stage 2.8-3.0 -> 2.8-2.9 ms
// on void_impact, 3.5-3.7 -> 3.2-3.4 ms on fcc 1 M. The distances themselves still take about a
// sixth of the stage: the divider's, not memory's (fetching their depths ahead changed nothing).
void half_resolution_row_by_row(HalfPass &pass, const HalfPhases &phases, RowsToBuild *rows) {
  BandFrame &band = *pass.band;
  const int blur_begin = std::max(0, pass.u0), blur_end = std::min(pass.u1, pass.rows);
  const int y_end = band.owned.y1;
  int blurred = blur_begin;       // blurred rows [blur_begin, blurred) are done
  int upsampled = band.owned.y0;  // owned rows [owned.y0, upsampled) are done
  // The held rows before reach(y) are built before row y is read: an estimate at row y reads
  // rows up to kMaxAoPixels away, and the rows next to its own; an owned row y reads its own, and
  // the estimates of its lone pixels as an estimate does.
  const auto reach = [](int y) { return y + kMaxAoPixels + 2; };
  const auto blur_and_upsample = [&](int done) {  // estimate rows [e0, done) are done
    // Blurred row k reads estimate rows k - kBlurReach .. k + kBlurReach of [e0, e1).
    while (blurred < blur_end && (blurred + kBlurReach < done || done == pass.e1)) {
      phases.blur(pass, blurred, blurred + 1);
      ++blurred;
    }
    // Owned row y reads blurred rows up to y / 2 + kSearchAhead; those beyond the image were
    // cleared with the pass.
    while (upsampled < y_end && (upsampled / 2 + kSearchAhead < blurred || blurred == blur_end)) {
      rows->up_to(reach(upsampled));
      phases.upsample(pass, upsampled, upsampled + 1);
      ++upsampled;
    }
  };
  for (int j = pass.e0; j < pass.e1; ++j) {
    rows->up_to(reach(2 * j));
    phases.estimate(pass, j, j + 1);
    blur_and_upsample(j + 1);
  }
  blur_and_upsample(pass.e1);
  rows->up_to(rows->positions->last_row());
}

void half_resolution(const ViewPositions &v, const AmbientOcclusionStyle &style, BandFrame *band,
                     const HalfPhases &phases, AoScratch *scratch, int threads, RowsToBuild *rows) {
  if (band->owned.y0 >= band->owned.y1) {
    if (rows != nullptr) rows->up_to(v.last_row(), threads);
    return;
  }
  HalfPass pass(v, style, band, scratch);
  if (rows != nullptr && parts_for(threads, pass.e1 - pass.e0, kMinRowsPerPart) == 1) {
    half_resolution_row_by_row(pass, phases, rows);
    return;
  }
  if (rows != nullptr) rows->up_to(v.last_row(), threads);  // several parts: every row first
  const auto over = [threads](int begin, int end, void (*phase)(HalfPass &, int, int),
                              HalfPass &p) {
    const int64_t count = std::max(0, end - begin);
    run_in_parts(parts_for(threads, count, kMinRowsPerPart), count,
                 [&](int, int64_t a, int64_t b) { phase(p, begin + int(a), begin + int(b)); });
  };
  over(pass.e0, pass.e1, phases.estimate, pass);
  over(std::max(0, pass.u0), std::min(pass.u1, pass.rows), phases.blur, pass);
  over(band->owned.y0, band->owned.y1, phases.upsample, pass);
}

// The path kAuto takes. Measured with lantern-bench-cues --kernels 9 (thread CPU time of the pass
// on a whole 1024^2 frame, void_impact; fcc 1 M alike): on an Intel Xeon with AVX-512 (Sapphire
// Rapids class), AVX2 with gathers 4.8 ms, the AVX-512 compilation 5.3-5.4, AVX2 with loads
// 5.2-5.4; on the AMD EPYCs of earlier measurements the AVX-512 compilation was about 8 % faster
// than AVX2, and gathers slower than loads.
AoVectorPath automatic_path() {
  if (cpu_prefers_gathers()) return AoVectorPath::kAvx2Gather;
  if (cpu_has_avx512_bw()) return AoVectorPath::kAvx512;
  if (cpu_has_avx2()) return AoVectorPath::kAvx2;
  return AoVectorPath::kPortable;
}

}  // namespace

int screen_ambient_occlusion_halo(const AmbientOcclusionStyle &style) {
  // Half: owned row y reads blurred estimate rows y / 2 - kSearchBehind .. y / 2 + kSearchAhead,
  // whose pixels lie on image rows y - 1 - 2 kSearchBehind .. y + 2 kSearchAhead; the blur reads
  // kBlurReach estimate rows (2 kBlurReach image rows) beyond those, and each estimate
  // kMaxAoPixels image rows beyond itself: y - 39 .. y + 39 (and only y + 39 needs 40 rows).
  // A pixel left without an estimate reads kMaxAoPixels rows, as at full resolution.
  return style.half_resolution ? kMaxAoPixels + 2 * (kBlurReach + kSearchAhead) : kMaxAoPixels;
}

namespace {

void apply(const ViewPositions &v, const AmbientOcclusionStyle &style, BandFrame *band,
           AoVectorPath path, AoScratch *scratch, int threads, RowsToBuild *rows) {
  AoScratch own;
  if (scratch == nullptr) scratch = &own;
  if (!style.half_resolution) {
    if (rows != nullptr) rows->up_to(v.last_row(), threads);
    full_resolution(v, style, band, threads);
    return;
  }
  static constexpr HalfPhases kAvx512{estimate_avx512, blur_avx512, upsample_avx512};
  static constexpr HalfPhases kAvx2Gather{estimate_avx2_gather, blur_avx2, upsample_avx2_gather};
  static constexpr HalfPhases kAvx2{estimate_avx2, blur_avx2, upsample_avx2};
  static constexpr HalfPhases kPortable{estimate_portable, blur_portable, upsample_portable};
  if (path == AoVectorPath::kAuto) path = automatic_path();
  const HalfPhases &phases = path == AoVectorPath::kAvx512 && cpu_has_avx512_bw()  ? kAvx512
                             : path == AoVectorPath::kAvx2Gather && cpu_has_avx2() ? kAvx2Gather
                             : path == AoVectorPath::kAvx2 && cpu_has_avx2()       ? kAvx2
                                                                                   : kPortable;
  half_resolution(v, style, band, phases, scratch, threads, rows);
}

}  // namespace

void apply_screen_ambient_occlusion(const ViewPositions &v, const AmbientOcclusionStyle &style,
                                    BandFrame *band, AoVectorPath path, AoScratch *scratch,
                                    int threads) {
  apply(v, style, band, path, scratch, threads, nullptr);
}

void build_positions_and_apply_screen_ambient_occlusion(ViewPositions *positions,
                                                        const Camera &camera,
                                                        const AmbientOcclusionStyle &style,
                                                        BandFrame *band, AoVectorPath path,
                                                        AoScratch *scratch, int threads) {
  positions->begin(*band, camera);
  RowsToBuild rows{positions, band, &camera, positions->first_row()};
  apply(*positions, style, band, path, scratch, threads, &rows);
}

}  // namespace lantern
