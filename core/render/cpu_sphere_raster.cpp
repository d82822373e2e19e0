#include "core/render/cpu_sphere_raster.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <glm/geometric.hpp>

#include "core/render/centred_cylinder_cast.h"
#include "core/render/cylinder_cast.h"
#include "core/render/screen_door.h"
#include "core/render/shading.h"
#include "core/view/reference_ray_grid.h"

namespace lantern {
namespace {

// Pixels are ray-cast in square tiles of side kTile, or kSmallTile for spheres that small
// (PixelRays pads its tables for the overrun).
constexpr int kTile = PixelRays::kPadding;
constexpr int kSmallTile = 4;
constexpr int kTilePixels = kTile * kTile;
// Window depth of a ray that misses or is clipped: loses every depth test (depths are <= 1).
constexpr float kMiss = 2.0f;

}  // namespace

void CpuSphereRaster::clear_target(const ViewGeometry &g, const uint8_t background[4],
                                   Frame *frame) {
  // Also after a move (asynchronous writing takes the frame): sizes, not just the dimensions.
  const size_t pixels = size_t(g.width) * size_t(g.height);
  if (frame->width != g.width || frame->height != g.height || frame->depth.size() != pixels ||
      frame->rgba.size() != 4 * pixels)
    *frame = Frame(g.width, g.height);
  frame->clear(background);
}

void CpuSphereRaster::begin_strip(const ViewGeometry &g, Frame *frame, int x0, int x1) {
  g_ = g;
  frame_ = frame;
  x0_ = std::max(x0, 0), x1_ = std::min(x1, g.width - 1);
  // The strip's pyramid reads no column past the strip: other threads write those.
  pyramid_.reset(frame->depth.data(), g.width, g.height, kBackgroundDepth, x1_ + 1);
  pending_ = PixelRect{};
  touched_ = PixelRect{};
  rays_.reset(g);
}

void CpuSphereRaster::set_lighting(const Lighting &lighting) {
  if (lighting.is_default())
    light_.reset();
  else
    light_.emplace(lighting);
}

namespace {

// A tile of n x n pixels (n = kTile or kSmallTile), ray-cast for one sphere: the window depth of
// each pixel's hit (kMiss where the ray misses the sphere, the hit is clipped by the near or far
// plane, or the pixel lies outside the w x h part asked for) and the squared Lambert factor of the
// shading. Pixel (k, j) of the tile is entry j * n + k. A small sphere fits one tile, so its pixels
// are cast in one straight-line loop that the compiler turns into vector instructions.
struct Tile {
  float wz[kTilePixels];
  float lambert2[kTilePixels];
};

// The float path, for every sphere wholly in front of the eye (all that dense scenes draw). It
// works relative to the ray through the sphere's centre, in quantities of order one or smaller:
// the large part of the window depth (that of the centre) is computed once per sphere in double
// and float adds only the small offset, so depths stay within about one float ulp of the double
// computation, and the silhouette test within float rounding of the pixel position. A pixel's
// offset from the centre's ray is (integer columns from a reference column) x step + the
// reference's own offset, so it depends on the pixel and the sphere only, never on the tile.
//
// Perspective, D = (rx, ry, -1) the ray, d = -c.z, (u0, v0) = (c.x, c.y) / d the centre's ray,
// (dx, dy) = (rx, ry) - (u0, v0): with L0^2 = 1 + u0^2 + v0^2, e = u0 dx + v0 dy,
//   |D|^2 = L^2 = L0^2 + 2e + dx^2 + dy^2,   c.D / d = L0^2 + e,
//   |c x D|^2 / d^2 = dx^2 + dy^2 + (u0 dy - v0 dx)^2      (no cancellation),
//   (hL/d)^2 = (r/d)^2 L^2 - |c x D|^2 / d^2               (h: half chord; hit iff > 0),
// the hit at view depth d (L0^2 + e - hL/d) / L^2, and window depth wa + wb / depth =
// (wa + wb/d) + (wb/d) delta with delta = (e + dx^2 + dy^2 + hL/d) / (L0^2 + e - hL/d).
// Orthographic: the hit is h = sqrt(r^2 - dx^2 - dy^2) before the centre's depth d.
struct CentredCast : ReferenceRayGrid {
  // Usable when the sphere lies wholly in front of the eye (perspective), or always (ortho).
  static bool applies(const ViewGeometry &g, const glm::dvec3 &c, double r) {
    return g.orthographic || -c.z - r > 0.0;
  }
  CentredCast(const ViewGeometry &g, const PixelRays &rays, const glm::dvec3 &c, double r);

  bool orthographic;
  float u0 = 0, v0 = 0;      // the centre's ray (perspective) or ray origin (orthographic)
  float l0sq = 0, rho2 = 0;  // perspective: L0^2, (r / d)^2
  float r2 = 0;              // orthographic: r^2
  float wc = 0, wd = 0;      // perspective: wz = wc + wd delta; orthographic: wz = wc - wd h
  float lo = 0, hi = 0;      // clip: perspective near / d, far / d; ortho d - near, d - far
};

CentredCast::CentredCast(const ViewGeometry &g, const PixelRays &rays, const glm::dvec3 &c,
                         double r)
    : orthographic(g.orthographic) {
  const double d = -c.z;
  double cu = c.x, cv = c.y;
  if (orthographic) {
    r2 = float(r * r);
    wc = float(0.5 + 0.5 * g.p32 - 0.5 * g.p22 * d), wd = float(-0.5 * g.p22);
    lo = float(d - g.near_plane), hi = float(d - g.far_plane);
  } else {
    cu /= d, cv /= d;
    l0sq = float(1.0 + cu * cu + cv * cv), rho2 = float((r / d) * (r / d));
    wc = float(0.5 - 0.5 * g.p22 + 0.5 * g.p32 / d), wd = float(0.5 * g.p32 / d);
    lo = float(g.near_plane / d), hi = float(g.far_plane / d);
  }
  // Centres on an axis to within 1e-30 count as on it: their products would be float
  // denormals, which are slow.
  u0 = std::abs(cu) < 1e-30 ? 0.0f : float(cu), v0 = std::abs(cv) < 1e-30 ? 0.0f : float(cv);
  // Reference column and row: those of the centre's ray (any fixed pair would do).
  place(rays, cu, cv);
}

// The tile kernels below come in an AVX-512, an AVX2 and a baseline clone, picked at load time.
// All run the same IEEE operations in the same order (this file is built with -ffp-contract=off,
// so the AVX-512 clone, whose instruction set has FMA, contracts nothing), so their results are
// bit-identical: an image does not depend on the machine's vector width (the 1214 image hashes
// are the same with the AVX-512 clone as with the AVX2 one). The AVX-512 clone casts a 1 M-atom
// LJ frame's tiles in about 1.2 ms a rank against 1.7 (perf, 3 alternated runs).
#if defined(__x86_64__) && defined(__GNUC__)
#define LANTERN_TILE_KERNEL __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define LANTERN_TILE_KERNEL
#endif

#define LANTERN_INLINE inline __attribute__((always_inline))

// The pixel kx columns and jy rows from the sphere's reference pixel, perspective; `inside`
// false makes it a miss. Every path casts a pixel through here, in the same operations.
LANTERN_INLINE void perspective_pixel(const CentredCast &p, int kx, int jy, bool inside,
                                      float *wz_out, float *lambert2_out) {
  const float dx = p.off_x + float(kx) * p.step_x, dy = p.off_y + float(jy) * p.step_y;
  const float dd = dx * dx + dy * dy, e = p.u0 * dx + p.v0 * dy;
  const float cross = p.u0 * dy - p.v0 * dx;
  const float l2 = p.l0sq + 2.0f * e + dd;
  const float h2 = p.rho2 * l2 - (dd + cross * cross);
  const float s = std::sqrt(std::max(h2, 0.0f));
  const float den = p.l0sq + e - s;  // view depth / d, times L^2
  // The shader's clip-z discard: view depth d den / L^2 outside [near, far].
  const bool hit = inside & (h2 > 0.0f) & (den >= p.lo * l2) & (den <= p.hi * l2);
  const float wz = p.wc + p.wd * ((e + dd + s) / den);
  *wz_out = hit ? wz : kMiss;
  *lambert2_out = h2 / (p.rho2 * l2);
}

// The same, orthographic.
LANTERN_INLINE void orthographic_pixel(const CentredCast &p, int kx, int jy, bool inside,
                                       float *wz_out, float *lambert2_out) {
  const float dx = p.off_x + float(kx) * p.step_x, dy = p.off_y + float(jy) * p.step_y;
  const float h2 = p.r2 - (dx * dx + dy * dy);
  const float s = std::sqrt(std::max(h2, 0.0f));
  const bool hit = inside & (h2 > 0.0f) & (s <= p.lo) & (s >= p.hi);
  const float wz = p.wc - p.wd * s;
  *wz_out = hit ? wz : kMiss;
  *lambert2_out = h2 / p.r2;
}

// Pixels (x0 + k, y0 + j), k < w, j < h, of a tile of side n, as straight-line loops over the
// tile's first h rows (the rows below are never read: the depth test stops at row h).
template <int n>
LANTERN_INLINE void cast_tile(const CentredCast &sphere, int x0, int y0, int w, int h, Tile *t) {
  const CentredCast p = sphere;  // a local copy: the tile's stores cannot alias it
  const int kx = x0 - p.ref_x, jy = y0 - p.ref_y;
  if (p.orthographic) {
    for (int i = 0; i < n * h; ++i)
      orthographic_pixel(p, kx + i % n, jy + i / n, i % n < w, &t->wz[i], &t->lambert2[i]);
  } else {
    for (int i = 0; i < n * h; ++i)
      perspective_pixel(p, kx + i % n, jy + i / n, i % n < w, &t->wz[i], &t->lambert2[i]);
  }
}

// A tile of side n (kTile or kSmallTile) of a sphere wholly in front of the eye.
LANTERN_TILE_KERNEL void cast_centred(const CentredCast &p, int n, int x0, int y0, int w, int h,
                                      Tile *t) {
  if (n == kSmallTile)
    cast_tile<kSmallTile>(p, x0, y0, w, h, t);
  else
    cast_tile<kTile>(p, x0, y0, w, h, t);
}

// The general path in double, for spheres reaching behind the eye plane (near-plane clipping),
// with the unnormalised ray D = (rx, ry, -1) from the eye: (hL)^2 = r^2 L^2 - (|c|^2 L^2 -
// (c.D)^2), the hit at view depth t / L^2 with t = c.D - hL.
class GeneralCast {
 public:
  GeneralCast(const ViewGeometry &g, const PixelRays &rays, const glm::dvec3 &c, double r)
      : rays_(rays),
        c_(c),
        r2_(r * r),
        c2_(glm::dot(c, c)),
        near_(g.near_plane),
        far_(g.far_plane),
        wa_(0.5 - 0.5 * g.p22),
        wb_(0.5 * g.p32) {}

  // The unit normal and the unit vector towards the eye at pixel (x, y)'s hit (custom lighting).
  void surface(int x, int y, float n[3], float v[3]) const {
    const double rx = rays_.x_data()[x], ry = rays_.y_data()[y];
    const double l2 = rx * rx + ry * ry + 1.0, cd = c_.x * rx + c_.y * ry - c_.z;
    const double tt = (cd - std::sqrt(std::max(r2_ * l2 - (c2_ * l2 - cd * cd), 0.0))) / l2;
    const glm::dvec3 normal = glm::normalize(tt * glm::dvec3(rx, ry, -1.0) - c_);
    const double inv_l = 1.0 / std::sqrt(l2);
    n[0] = float(normal.x), n[1] = float(normal.y), n[2] = float(normal.z);
    v[0] = float(-rx * inv_l), v[1] = float(-ry * inv_l), v[2] = float(inv_l);
  }

  void cast(int n, int x0, int y0, int w, int h, Tile *t) const {
    const double *ray_x = rays_.x_data() + x0, *ray_y = rays_.y_data() + y0;  // padded tables
    for (int i = 0; i < n * n; ++i) {
      const int k = i % n, j = i / n;
      const double rx = ray_x[k], ry = ray_y[j];
      const double l2 = rx * rx + ry * ry + 1.0, cd = c_.x * rx + c_.y * ry - c_.z;
      const double h2l2 = r2_ * l2 - (c2_ * l2 - cd * cd);
      const double tt = cd - std::sqrt(std::max(h2l2, 0.0));
      const bool hit = (k < w) & (j < h) & (h2l2 > 0.0) & (tt >= near_ * l2) & (tt <= far_ * l2);
      const float wz = float(wa_ + wb_ * l2 / tt);
      t->wz[i] = hit ? wz : kMiss;
      t->lambert2[i] = float(h2l2 / (r2_ * l2));
    }
  }

 private:
  const PixelRays &rays_;
  glm::dvec3 c_;
  double r2_, c2_, near_, far_, wa_, wb_;
};

// The unit normal and unit vector towards the eye at the hit of pixel (x, y) of a sphere wholly in
// front of the eye, for custom lighting: perspective with t = view depth / (d L^2 / L^2) = den/L^2
// the hit is d t (rx, ry, -1), so the normal is along (t dx - (1 - t) u0, t dy - (1 - t) v0,
// 1 - t) with 1 - t = (e + dx^2 + dy^2 + s) / L^2 (no cancellation); orthographic (dx, dy, s).
void centred_surface(const CentredCast &p, int x, int y, float n[3], float v[3]) {
  const float dx = p.off_x + float(x - p.ref_x) * p.step_x;
  const float dy = p.off_y + float(y - p.ref_y) * p.step_y;
  const float dd = dx * dx + dy * dy;
  float m[3];
  if (p.orthographic) {
    m[0] = dx, m[1] = dy, m[2] = std::sqrt(std::max(p.r2 - dd, 0.0f));
    v[0] = 0.0f, v[1] = 0.0f, v[2] = 1.0f;
  } else {
    const float e = p.u0 * dx + p.v0 * dy, cross = p.u0 * dy - p.v0 * dx;
    const float l2 = p.l0sq + 2.0f * e + dd;
    const float s = std::sqrt(std::max(p.rho2 * l2 - (dd + cross * cross), 0.0f));
    const float one_minus_t = (e + dd + s) / l2, t = 1.0f - one_minus_t;
    m[0] = t * dx - one_minus_t * p.u0, m[1] = t * dy - one_minus_t * p.v0, m[2] = one_minus_t;
    const float inv_l = 1.0f / std::sqrt(l2);
    v[0] = -(p.u0 + dx) * inv_l, v[1] = -(p.v0 + dy) * inv_l, v[2] = inv_l;
  }
  const float length = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  const float inv = length > 0.0f ? 1.0f / length : 0.0f;
  n[0] = m[0] * inv, n[1] = m[1] * inv, n[2] = m[2] * inv;
}

// A custom lighting's color (shading.h's LightModel), rounded as shade_pixel rounds.
uint32_t shade_lit(const shading::LightModel<float> &light, const float n[3], const float v[3],
                   const uint8_t rgb[3]) {
  const auto unorm8 = [](float x) { return uint32_t(int32_t(std::min(x, 1.0f) * 255.0f + 0.5f)); };
  float factor, highlight;
  light.terms(n, v, &factor, &highlight);
  factor *= 1.0f / 255.0f;
  return unorm8(float(rgb[0]) * factor + highlight) |
         unorm8(float(rgb[1]) * factor + highlight) << 8 |
         unorm8(float(rgb[2]) * factor + highlight) << 16;
}

// The impostor shader's headlight (shading.h): Lambert (light along the view ray) plus a
// Blinn-Phong highlight, clamped, to 8 bits; packed as R | G << 8 | B << 16.
static_assert(shading::kShininess == 40,
              "shade_pixel raises lambert to the power 40 by squaring (l32 * l8): rewrite that "
              "product for the new exponent");
LANTERN_INLINE uint32_t shade_pixel(float lambert2, float red, float green, float blue) {
  using shading::kAmbient, shading::kDiffuse, shading::kSpecular;
  const auto unorm8 = [](float v) { return uint32_t(int32_t(std::min(v, 1.0f) * 255.0f + 0.5f)); };
  const float lambert = std::sqrt(std::max(lambert2, 0.0f));
  const float l2 = lambert * lambert, l4 = l2 * l2, l8 = l4 * l4, l32 = (l8 * l8) * (l8 * l8);
  const float diffuse = (kAmbient<float> + kDiffuse<float> * lambert) * (1.0f / 255.0f),
              highlight = kSpecular<float> * l32 * l8;
  return unorm8(red * diffuse + highlight) | unorm8(green * diffuse + highlight) << 8 |
         unorm8(blue * diffuse + highlight) << 16;
}

// The first h rows of a tile of side n. The colour is read once and the arrays do not overlap:
// else the compiler reloads the colour for every pixel (a store might have changed it) and checks
// the arrays for overlap on every call (1.9 -> 1.2 ms of a rank's 1 M-atom LJ frame, perf).
template <int n>
LANTERN_INLINE void shade_tile_n(int h, const float *__restrict lambert2, const uint8_t rgb[3],
                                 uint32_t *__restrict out) {
  const float red = rgb[0], green = rgb[1], blue = rgb[2];
  for (int i = 0; i < n * h; ++i) out[i] = shade_pixel(lambert2[i], red, green, blue);
}

LANTERN_TILE_KERNEL void shade_tile(int n, int h, const float *__restrict lambert2,
                                    const uint8_t rgb[3], uint32_t *__restrict out) {
  if (n == kSmallTile)
    shade_tile_n<kSmallTile>(h, lambert2, rgb, out);
  else
    shade_tile_n<kTile>(h, lambert2, rgb, out);
}

// A color of shade_pixel as compositing's word R<<24 | G<<16 | B<<8 | A (alpha 255), and the word
// of 4 bytes of the frame: the smaller word wins a depth tie, here as in compositing.
LANTERN_INLINE uint32_t shaded_word(uint32_t color) {
  return (color & 0xFFu) << 24 | (color & 0xFF00u) << 8 | (color & 0xFF0000u) >> 8 | 0xFFu;
}
LANTERN_INLINE uint32_t frame_word(const uint8_t *rgba) {
  return uint32_t(rgba[0]) << 24 | uint32_t(rgba[1]) << 16 | uint32_t(rgba[2]) << 8 | rgba[3];
}

// The pixels of a tile of side n at (x0, y0), w x h of them, that a see-through sphere keeps
// (bit j * n + k for pixel (x0 + k, y0 + j)).
uint64_t screen_door_mask(int n, int x0, int y0, int w, int h, uint8_t alpha8) {
  uint64_t keep = 0;
  for (int j = 0; j < h; ++j)
    for (int k = 0; k < w; ++k)
      keep |= uint64_t(screen_door_keeps(x0 + k, y0 + j, alpha8)) << (j * n + k);
  return keep;
}

// Cylinder pixels are cast and depth-tested kRun at a time.
constexpr int kRun = 8;

// Pixels of a cylinder wholly in front of the eye, cast kRun at a time in one call: pixel i is
// (xs[i], ys[i]) (the rows' pixels one after another, so that short rows share vectors); count
// is a multiple of kRun. cylinder_pixel: a pixel's result does not depend on the lane or the call
// it is cast in.
LANTERN_TILE_KERNEL void cast_cylinder_pixels(const CentredCylinder &cylinder,
                                              const int *__restrict xs, const int *__restrict ys,
                                              int count, float *__restrict wz,
                                              float *__restrict lambert2) {
  const CentredCylinder p = cylinder;  // a local copy: the stores cannot alias it
  if (p.orthographic) {
    for (int i = 0; i < count; ++i)
      cylinder_pixel(p, xs[i] - p.ref_x, ys[i] - p.ref_y, &wz[i], &lambert2[i]);
  } else {
    for (int i = 0; i < count; ++i)
      cylinder_pixel(p, xs[i] - p.ref_x, ys[i] - p.ref_y, &wz[i], &lambert2[i]);
  }
}

// Appends the n pixels (x0 .. x0 + n - 1, y) to the cast lists at xs, ys, with the depths
// row_depth holds there, kRun entries at a time (entries up to the next multiple of kRun are
// written too: the lists have room). `whole`: kRun depths may be read from any column of the run.
LANTERN_INLINE void put_run(int *xs, int *ys, float *held, int x0, int y, const float *row_depth,
                            int n, bool whole) {
  for (int k = 0; k < n; k += kRun) {
#if defined(__SSE2__)
    const __m128i first = _mm_add_epi32(_mm_set1_epi32(x0 + k), _mm_setr_epi32(0, 1, 2, 3));
    _mm_storeu_si128(reinterpret_cast<__m128i *>(xs + k), first);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(xs + k + 4),
                     _mm_add_epi32(first, _mm_set1_epi32(4)));
    const __m128i row = _mm_set1_epi32(y);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(ys + k), row);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(ys + k + 4), row);
    if (whole) {
      _mm_storeu_ps(held + k, _mm_loadu_ps(row_depth + x0 + k));
      _mm_storeu_ps(held + k + 4, _mm_loadu_ps(row_depth + x0 + k + 4));
      continue;
    }
#else
    for (int j = 0; j < kRun; ++j) xs[k + j] = x0 + k + j, ys[k + j] = y;
#endif
    for (int j = 0; j < std::min(kRun, n - k); ++j) held[k + j] = row_depth[x0 + k + j];
  }
}

// kRun entries of padding after the last pixel: its position again, and a held depth that no
// depth test takes (every comparison with NaN is false).
LANTERN_INLINE void pad_run(int *xs, int *ys, float *held, int x, int y) {
  for (int k = 0; k < kRun; ++k)
    xs[k] = x, ys[k] = y, held[k] = std::numeric_limits<float>::quiet_NaN();
}

// Comparisons of n <= kRun consecutive depths, as bits (bit k for entry k): where depth[k] >= z
// (the pixels the early depth reject keeps), and where wz[k] < depth[k] and wz[k] == depth[k].
// `whole`: kRun entries may be read from depth (not past the frame's end), whatever n.
struct RunBits {
  uint32_t nearer, tied;
};
#if defined(__SSE2__)
LANTERN_INLINE uint32_t low_bits(int n) {
  return (uint32_t(1) << n) - 1;
}
LANTERN_INLINE uint32_t kept_bits(const float *depth, int n, float z, bool whole) {
  if (whole) {
    const __m128 zz = _mm_set1_ps(z);
    const int lo = _mm_movemask_ps(_mm_cmpge_ps(_mm_loadu_ps(depth), zz));
    const int hi = _mm_movemask_ps(_mm_cmpge_ps(_mm_loadu_ps(depth + 4), zz));
    return uint32_t(lo | hi << 4) & low_bits(n);
  }
  uint32_t bits = 0;
  for (int k = 0; k < n; ++k) bits |= uint32_t(depth[k] >= z) << k;
  return bits;
}
LANTERN_INLINE RunBits depth_bits(const float *wz, const float *depth, int n, bool whole) {
  if (whole) {
    const __m128 w0 = _mm_loadu_ps(wz), w1 = _mm_loadu_ps(wz + 4);
    const __m128 d0 = _mm_loadu_ps(depth), d1 = _mm_loadu_ps(depth + 4);
    const uint32_t nearer = uint32_t(_mm_movemask_ps(_mm_cmplt_ps(w0, d0)) |
                                     _mm_movemask_ps(_mm_cmplt_ps(w1, d1)) << 4);
    const uint32_t tied = uint32_t(_mm_movemask_ps(_mm_cmpeq_ps(w0, d0)) |
                                   _mm_movemask_ps(_mm_cmpeq_ps(w1, d1)) << 4);
    return {nearer & low_bits(n), tied & low_bits(n)};
  }
  RunBits bits{0, 0};
  for (int k = 0; k < n; ++k) {
    bits.nearer |= uint32_t(wz[k] < depth[k]) << k;
    bits.tied |= uint32_t(wz[k] == depth[k]) << k;
  }
  return bits;
}
#else
LANTERN_INLINE uint32_t kept_bits(const float *depth, int n, float z, bool) {
  uint32_t bits = 0;
  for (int k = 0; k < n; ++k) bits |= uint32_t(depth[k] >= z) << k;
  return bits;
}
LANTERN_INLINE RunBits depth_bits(const float *wz, const float *depth, int n, bool) {
  RunBits bits{0, 0};
  for (int k = 0; k < n; ++k) {
    bits.nearer |= uint32_t(wz[k] < depth[k]) << k;
    bits.tied |= uint32_t(wz[k] == depth[k]) << k;
  }
  return bits;
}
#endif

// The frame a raster draws into, for the tile loops below.
struct Target {
  float *depth;
  uint8_t *rgba;
  int width, height;
  const shading::LightModel<float> *light;  // null: the default headlight
  int last_column;                          // the strip's last column: none past it is written
  // Whether this strip holds every column, so that a read may run on past a row's end into the
  // next row (no other thread writes any column). Otherwise no column past last_column is read
  // either: other threads write them (column_strips.h), and a vector read of them, even with its
  // extra lanes dropped, would race with their writes.
  bool wraps;
};

// Writes a color of shade_pixel (R | G << 8 | B << 16) to 4 bytes of the frame as R, G, B, 255:
// one 32-bit store where bytes are little-endian, the same bytes as four byte stores.
LANTERN_INLINE void store_color(uint8_t *out, uint32_t color) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  const uint32_t word = color | 0xFF000000u;
  std::memcpy(out, &word, sizeof word);
#else
  out[0] = uint8_t(color), out[1] = uint8_t(color >> 8), out[2] = uint8_t(color >> 16);
  out[3] = 255;
#endif
}

#if defined(__SSE2__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define LANTERN_BLEND_ROWS 1
// Writes the pixels of one tile row that the sphere won (bit k of `won` for column k < n): their
// depths from wz and colors (shade_pixel's, as store_color writes them) from color, 4 columns
// per vector, the other columns rewritten with what they hold. A few whole-vector stores instead
// of two stores a pixel, which fill the store buffer when the row's lines are still on their way.
// The n columns must lie in the caller's strip (no other thread writes them) and in the frame.
template <int n>
LANTERN_INLINE void blend_row(uint32_t won, const float *wz, const uint32_t *color, float *depth,
                              uint8_t *rgba) {
  const __m128i lane_bits = _mm_setr_epi32(1, 2, 4, 8), alpha = _mm_set1_epi32(int(0xFF000000u));
  for (int q = 0; q < n; q += 4) {
    const uint32_t bits = won >> q & 0xFu;
    if (!bits) continue;
    const __m128 new_depth = _mm_loadu_ps(wz + q);
    const __m128i new_rgba =
        _mm_or_si128(_mm_loadu_si128(reinterpret_cast<const __m128i *>(color + q)), alpha);
    __m128i *out = reinterpret_cast<__m128i *>(rgba + 4 * q);
    if (bits == 0xFu) {
      _mm_storeu_ps(depth + q, new_depth);
      _mm_storeu_si128(out, new_rgba);
      continue;
    }
    const __m128i keep =
        _mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(int(bits)), lane_bits), lane_bits);
    const __m128 keep_ps = _mm_castsi128_ps(keep);
    _mm_storeu_ps(depth + q, _mm_or_ps(_mm_and_ps(keep_ps, new_depth),
                                       _mm_andnot_ps(keep_ps, _mm_loadu_ps(depth + q))));
    _mm_storeu_si128(out, _mm_or_si128(_mm_and_si128(keep, new_rgba),
                                       _mm_andnot_si128(keep, _mm_loadu_si128(out))));
  }
}
#endif

// Depth test of one tile row: bit k of *nearer where wz[k] < depth[k], of *tied where they are
// equal, for k < w. `whole`: n depths may be read (the row does not end the frame), so the
// comparisons run as vectors over all n and the bits past w are dropped; the same bits.
template <int n>
LANTERN_INLINE void depth_row(const float *wz, const float *depth, int w, bool whole,
                              uint32_t *nearer, uint32_t *tied) {
#if defined(__SSE2__)
  if (whole) {
    uint32_t lt = 0, eq = 0;
    for (int q = 0; q < n; q += 4) {
      const __m128 a = _mm_loadu_ps(wz + q), d = _mm_loadu_ps(depth + q);
      lt |= uint32_t(_mm_movemask_ps(_mm_cmplt_ps(a, d))) << q;
      eq |= uint32_t(_mm_movemask_ps(_mm_cmpeq_ps(a, d))) << q;
    }
    const uint32_t low = (uint32_t(1) << w) - 1;
    *nearer = lt & low, *tied = eq & low;
    return;
  }
#endif
  uint32_t lt = 0, eq = 0;
  for (int k = 0; k < w; ++k) {
    lt |= uint32_t(wz[k] < depth[k]) << k;
    eq |= uint32_t(wz[k] == depth[k]) << k;
  }
  *nearer = lt, *tied = eq;
}

// Ray-casts a sphere (the float cast `centred` when there is one, else `general`) over `rect`
// (within the strip) in tiles of side n, depth-tests and shades them and writes the pixels it
// wins. Returns the rectangle of the pixels written.
template <int n>
PixelRect draw_tiles(const CentredCast *centred, const GeneralCast *general, const uint8_t rgb[3],
                     const PixelRect &rect, uint8_t alpha8, const Target &f) {
  static_assert(n * n <= 64, "a tile's pixels are bits of one word");
  const size_t width = size_t(f.width);
  // The rows' colours are written only after the cast and the depth test: ask for their lines
  // now, so that the stores do not wait on them (only a hint to the cache).
  for (int y = rect.y0; y <= rect.y1; ++y) {
    const uint8_t *row = f.rgba + 4 * (size_t(y) * width);
    __builtin_prefetch(row + 4 * size_t(rect.x0), 1, 3);
    __builtin_prefetch(row + 4 * size_t(rect.x1), 1, 3);
  }
  PixelRect written;
  for (int y0 = rect.y0; y0 <= rect.y1; y0 += n)
    for (int x0 = rect.x0; x0 <= rect.x1; x0 += n) {
      const int w = std::min(n, rect.x1 - x0 + 1), h = std::min(n, rect.y1 - y0 + 1);
      Tile t;
      if (centred)
        cast_centred(*centred, n, x0, y0, w, h, &t);
      else
        general->cast(n, x0, y0, w, h, &t);
      // Depth test without branches: nearer wins; an equal depth is settled by color below.
      // n depths of a row can be read when they lie in the strip, or, where the strip holds
      // every column, unless the tile passes the row's end on the frame's last row (or the frame
      // is narrower than a tile).
      const bool whole =
          x0 + n - 1 <= f.last_column || (f.wraps && f.width >= n && y0 + h < f.height);
      uint64_t nearer = 0, tied = 0;
      for (int j = 0; j < h; ++j) {
        uint32_t lt, eq;
        depth_row<n>(t.wz + j * n, f.depth + size_t(y0 + j) * width + size_t(x0), w, whole, &lt,
                     &eq);
        nearer |= uint64_t(lt) << (j * n), tied |= uint64_t(eq) << (j * n);
      }
      if (alpha8 < 255) {
        const uint64_t keep = screen_door_mask(n, x0, y0, w, h, alpha8);
        nearer &= keep, tied &= keep;
      }
      if (!(nearer | tied)) continue;
      uint32_t color[kTilePixels];
      if (f.light) {
        for (uint64_t bits = nearer | tied; bits; bits &= bits - 1) {  // the pixels that may win
          const unsigned i = unsigned(__builtin_ctzll(bits));
          const int x = x0 + int(i % n), y = y0 + int(i / n);
          float nv[3], v[3];
          if (centred)
            centred_surface(*centred, x, y, nv, v);
          else
            general->surface(x, y, nv, v);
          color[i] = shade_lit(*f.light, nv, v, rgb);
        }
      } else {
        // Only the rows from the first to the last that may win (a pixel's color does not
        // depend on the rows shaded with it).
        const int j0 = __builtin_ctzll(nearer | tied) / n,
                  j1 = (63 - __builtin_clzll(nearer | tied)) / n;
        shade_tile(n, j1 - j0 + 1, t.lambert2 + j0 * n, rgb, color + j0 * n);
      }
      uint64_t won = nearer;
      for (uint64_t bits = tied; bits; bits &= bits - 1) {  // rare: exactly equal depths
        const unsigned i = unsigned(__builtin_ctzll(bits));
        const uint8_t *out =
            f.rgba + 4 * (size_t(y0) * width + size_t(x0) + (i / n) * width + i % n);
        if (shaded_word(color[i]) < frame_word(out)) won |= uint64_t(1) << i;
      }
      if (!won) continue;
      int kmin = n, kmax = -1;
#if defined(LANTERN_BLEND_ROWS)
      if (!f.light && x0 + n - 1 <= f.last_column) {
        // Every color of the rows holding a won pixel is set (shade_tile): rows at once.
        uint32_t columns = 0;
        const size_t p0 = size_t(y0) * width + size_t(x0);
        for (int j = 0; j < h; ++j) {
          const uint32_t row = uint32_t(won >> (j * n)) & ((uint32_t(1) << n) - 1);
          if (!row) continue;
          columns |= row;
          const size_t p = p0 + size_t(j) * width;
          blend_row<n>(row, t.wz + j * n, color + j * n, f.depth + p, f.rgba + 4 * p);
        }
        kmin = __builtin_ctz(columns), kmax = 31 - __builtin_clz(columns);
      } else
#endif
        for (uint64_t bits = won; bits; bits &= bits - 1) {
          const unsigned i = unsigned(__builtin_ctzll(bits)), k = i % n;
          const size_t p = size_t(y0 + int(i / n)) * width + size_t(x0) + k;
          f.depth[p] = t.wz[i];
          store_color(f.rgba + 4 * p, color[i]);
          kmin = std::min(kmin, int(k)), kmax = std::max(kmax, int(k));
        }
      written.unite(PixelRect{x0 + kmin, y0 + __builtin_ctzll(won) / n, x0 + kmax,
                              y0 + (63 - __builtin_clzll(won)) / n});
    }
  return written;
}

}  // namespace

bool CpuSphereRaster::draw(const glm::dvec3 &c, double r, const uint8_t rgb[3], PixelRect rect,
                           uint8_t alpha8) {
  rect.x0 = std::max(rect.x0, x0_), rect.x1 = std::min(rect.x1, x1_);
  if (rect.empty() || !(r > 0.0)) return false;
  if (!g_.orthographic && glm::dot(c, c) <= r * r) return false;  // eye inside: nothing drawn
  // The per-pixel test alone decides which pixels a sphere covers (the caller's rectangle holds
  // them all), and a pixel's result does not depend on the tile it was cast in.
  std::optional<CentredCast> centred;  // the float path when it applies, else the double one
  std::optional<GeneralCast> general;
  if (CentredCast::applies(g_, c, r))
    centred.emplace(g_, rays_, c, r);
  else
    general.emplace(g_, rays_, c, r);
  const size_t width = size_t(g_.width);
  float *depth = frame_->depth.data();
  uint8_t *rgba = frame_->rgba.data();
  PixelRect written;
  if (centred && rect.x1 - rect.x0 < 3 && rect.y1 - rect.y0 < 3) {
    const CentredCast &fast = *centred;
    // A sphere of a pixel or so: its few pixels one by one, through the same pixel functions.
    for (int y = rect.y0; y <= rect.y1; ++y)
      for (int x = rect.x0; x <= rect.x1; ++x) {
        float wz, lambert2;
        if (fast.orthographic)
          orthographic_pixel(fast, x - fast.ref_x, y - fast.ref_y, true, &wz, &lambert2);
        else
          perspective_pixel(fast, x - fast.ref_x, y - fast.ref_y, true, &wz, &lambert2);
        const size_t p = size_t(y) * width + size_t(x);
        if (!(wz <= depth[p]) || (alpha8 < 255 && !screen_door_keeps(x, y, alpha8))) continue;
        uint32_t color;
        if (light_) {
          float n[3], v[3];
          centred_surface(fast, x, y, n, v);
          color = shade_lit(*light_, n, v, rgb);
        } else {
          color = shade_pixel(lambert2, rgb[0], rgb[1], rgb[2]);
        }
        uint8_t *out = rgba + 4 * p;
        if (!(wz < depth[p]) && !(shaded_word(color) < frame_word(out))) continue;
        depth[p] = wz;
        store_color(out, color);
        written.unite(PixelRect{x, y, x, y});
      }
    pyramid_.propagate(written);
    touched_.unite(written);
    return !written.empty();
  }
  // Tile side: small spheres get small tiles (a pixel's result does not depend on the tile).
  const Target target{
      depth, rgba, g_.width, g_.height, light_ ? &*light_ : nullptr, x1_, holds_every_column()};
  if (rect.x1 - rect.x0 < kSmallTile && rect.y1 - rect.y0 < kSmallTile)
    written = draw_tiles<kSmallTile>(centred ? &*centred : nullptr, general ? &*general : nullptr,
                                     rgb, rect, alpha8, target);
  else
    written = draw_tiles<kTile>(centred ? &*centred : nullptr, general ? &*general : nullptr, rgb,
                                rect, alpha8, target);
  pyramid_.propagate(written);
  touched_.unite(written);
  return !written.empty();
}

bool CpuSphereRaster::draw_bond(const glm::dvec3 &a, const glm::dvec3 &b, double r,
                                const uint8_t rgb[3], PixelRect rect, uint8_t alpha8) {
  rect.x0 = std::max(rect.x0, x0_), rect.x1 = std::min(rect.x1, x1_);
  const double length = glm::length(b - a);
  if (rect.empty() || !(r > 0.0) || !(length > 0.0)) return false;
  const glm::dvec3 u = (b - a) / length;
  // Early depth reject: no point of the cylinder is nearer than view depth `nearest`, so a pixel
  // already holding something nearer than that (lowered by the margin covered() takes) would
  // reject any hit - its cast is skipped and the image is that of casting it. Behind an atom's
  // sphere (the first part of every half-bond) and behind nearer bonds, most pixels go here.
  const double nearest = std::min(-a.z, -b.z) - r;
  const float reject =
      nearest > g_.near_plane ? float(g_.window_depth(nearest) - kQueryMargin) : -1.0f;
  if (CentredCylinder::applies(g_, a, b, r))
    return draw_centred_bond(a, u, length, r, rgb, rect, alpha8, reject);
  const size_t width = size_t(g_.width);
  float *depth = frame_->depth.data();
  uint8_t *rgba = frame_->rgba.data();
  const CylinderRows rows(g_, rays_, a, u, r, rect);
  const CylinderCast cylinder(g_.orthographic, a, u, length, r);
  PixelRect written;
  for (int y = rect.y0; y <= rect.y1; ++y) {
    int span0, span1;
    if (!rows.span(rays_, y, &span0, &span1)) continue;
    for (int x = span0; x <= span1; ++x) {
      const size_t p = size_t(y) * width + size_t(x);
      if (depth[p] < reject) continue;
      if (alpha8 < 255 && !screen_door_keeps(x, y, alpha8)) continue;
      const double rx = rays_.x(x), ry = rays_.y(y);
      CylinderHit hit;
      // The nearest surface only, as for spheres: clipped by a plane, the pixel shows nothing.
      if (!cylinder.cast(rx, ry, &hit) || hit.t < g_.near_plane || hit.t > g_.far_plane) continue;
      const float wz = float(g_.window_depth(hit.t));
      if (!(wz <= depth[p])) continue;
      uint32_t color;
      if (light_) {
        const glm::dvec3 view = cylinder.towards_eye(rx, ry);
        const float n[3] = {float(hit.normal.x), float(hit.normal.y), float(hit.normal.z)};
        const float v[3] = {float(view.x), float(view.y), float(view.z)};
        color = shade_lit(*light_, n, v, rgb);
      } else {
        color = shade_pixel(float(cylinder.lambert2(rx, ry, hit.normal)), rgb[0], rgb[1], rgb[2]);
      }
      uint8_t *out = rgba + 4 * p;
      if (!(wz < depth[p]) && !(shaded_word(color) < frame_word(out))) continue;
      depth[p] = wz;
      out[0] = uint8_t(color), out[1] = uint8_t(color >> 8), out[2] = uint8_t(color >> 16);
      out[3] = 255;
      written.unite(PixelRect{x, y, x, y});
    }
  }
  pyramid_.propagate(written);
  touched_.unite(written);
  return !written.empty();
}

bool CpuSphereRaster::draw_centred_bond(const glm::dvec3 &a, const glm::dvec3 &u, double length,
                                        double r, const uint8_t rgb[3], const PixelRect &rect,
                                        uint8_t alpha8, float reject) {
  const size_t width = size_t(g_.width);
  float *depth = frame_->depth.data();
  uint8_t *rgba = frame_->rgba.data();
  // Narrow rectangles are cast whole, row by row; wider ones only over the columns CylinderRows
  // keeps, which hold every pixel the float cast accepts.
  std::optional<CylinderRows> rows;
  if (rect.x1 - rect.x0 >= 2 * kRun) rows.emplace(g_, rays_, a, u, r, rect);
  // The rows the cylinder can meet. A hit of row y lies on a ray of the row, so in its plane:
  // n . q = 0 with n = (0, 1, ry) (perspective) or q.y = ry (orthographic); and within r of an
  // axis point s(tau) = a + tau u, tau in [0, length], which is then within r of the plane:
  // |h(tau)| <= r |n| <= r (1 + |ry|), h(tau) = n . s(tau) (less ry, orthographic) linear in tau,
  // so [h(0), h(length)] meets that interval. The float cast's rays stray from the row's plane
  // by less than `stray` (ray units, as CylinderRows' slack), which widens it by that times the
  // farthest depth.
  const glm::dvec3 b = a + length * u;
  const double ray_step = std::abs(rays_.x(1) - rays_.x(0)) + std::abs(rays_.y(1) - rays_.y(0));
  const double stray =
      0.01 * ray_step + 1e-6 * (std::abs(rays_.y(rect.y0)) + std::abs(rays_.y(rect.y1)) +
                                std::abs(a.y) / (g_.orthographic ? 1.0 : -a.z));
  const double far_end = g_.orthographic ? 1.0 : std::max(-a.z, -b.z) + r;
  const auto row_meets = [&](int y) {
    const double ry = rays_.y(y);
    const double ha = g_.orthographic ? a.y - ry : a.y + ry * a.z;
    const double hb = g_.orthographic ? b.y - ry : b.y + ry * b.z;
    const double reach =
        (r * (1.0 + (g_.orthographic ? 0.0 : std::abs(ry))) + stray * far_end) * (1.0 + 1e-9);
    return std::min(ha, hb) <= reach && std::max(ha, hb) >= -reach;
  };
  // The rows meeting it are consecutive when both ends lie more than 2 r in front of the eye (or
  // orthographic): h(0) and h(length), less or plus the reach, then all fall as ry grows (the
  // reach grows by r |d ry| at most, h by -z |d ry| > 2 r |d ry|), so each of the two tests holds
  // on one side of a row. Then they are found from both ends and the rows between not tested.
  // The pixels to cast, row after row: each row's span less the pixels the early depth reject
  // skips at both ends, as columns and rows, with the depths they hold now (nothing else writes
  // them before the depth test below). Runs are written kRun entries at a time, whatever their
  // length (the next run overwrites the excess), so the lists have room for kRun more.
  int y_first = rect.y0, y_last = rect.y1;
  const bool consecutive = g_.orthographic || std::min(-a.z, -b.z) > 2.0 * r;
  if (consecutive) {
    while (y_first <= y_last && !row_meets(y_first)) ++y_first;
    while (y_last > y_first && !row_meets(y_last)) --y_last;
  }
  int cast = 0;
  for (int y = y_first; y <= y_last; ++y) {
    int lo = rect.x0, hi = rect.x1;
    if (!consecutive && !row_meets(y)) continue;
    if (rows && !rows->span(rays_, y, &lo, &hi)) continue;
    const float *row_depth = depth + size_t(y) * width;
    // kRun depths can be read from column c when they lie in the strip, or, where the strip holds
    // every column (no other thread writes any), from any column but the last few of the frame's
    // last row.
    const bool last = y == g_.height - 1, wraps = holds_every_column();
    const auto readable = [&](int c) {
      return c + kRun - 1 <= x1_ || (wraps && (!last || c + kRun <= g_.width));
    };
    uint32_t keep = 0;
    if (hi - lo < kRun) {  // the usual short span: one scan finds both ends
      keep = kept_bits(row_depth + lo, hi - lo + 1, reject, readable(lo));
      if (!keep) continue;
      hi = lo + 31 - __builtin_clz(keep), lo += __builtin_ctz(keep);
    } else {
      for (; lo <= hi; lo += kRun)
        if ((keep = kept_bits(row_depth + lo, std::min(kRun, hi - lo + 1), reject, readable(lo))))
          break;
      if (!keep) continue;
      lo += __builtin_ctz(keep);
      for (;; hi -= kRun) {
        const int n = std::min(kRun, hi - lo + 1);
        if ((keep = kept_bits(row_depth + hi - n + 1, n, reject, readable(hi + 1 - n)))) {
          hi -= __builtin_clz(keep) - (32 - n);
          break;
        }
      }
    }
    const int n = hi - lo + 1;
    if (cast + n + 2 * kRun > cast_capacity_) grow_cast_lists(cast + n + 2 * kRun);
    put_run(cast_x_.data() + cast, cast_y_.data() + cast, cast_depth_.data() + cast, lo, y,
            row_depth, n, readable(hi));
    cast += n;
  }
  if (cast == 0) return false;
  const CentredCylinder cylinder(g_, rays_, a, u, length, r);
  int *xs = cast_x_.data(), *ys = cast_y_.data();
  float *held = cast_depth_.data();
  // Padded to whole vectors with the last pixel, which the depth test below never takes.
  const int padded = (cast + kRun - 1) / kRun * kRun;
  pad_run(xs + cast, ys + cast, held + cast, xs[cast - 1], ys[cast - 1]);
  float *wz = cast_wz_.data(), *lambert2 = cast_lambert2_.data();
  cast_cylinder_pixels(cylinder, xs, ys, padded, wz, lambert2);
  int won_x0 = g_.width, won_x1 = -1, won_y0 = g_.height, won_y1 = -1;
  for (int i0 = 0; i0 < cast; i0 += kRun) {
    // Depth test without branches, kRun pixels at a time: nearer wins; an equal depth is
    // settled by color below.
    const RunBits test = depth_bits(wz + i0, held + i0, kRun, true);
    const uint32_t nearer = test.nearer;
    for (uint32_t bits = test.nearer | test.tied; bits; bits &= bits - 1) {
      const int k = __builtin_ctz(bits), i = i0 + k, x = xs[i], y = ys[i];
      if (alpha8 < 255 && !screen_door_keeps(x, y, alpha8)) continue;
      uint32_t c;
      if (light_) {
        float nv[3], v[3];
        cylinder_surface(cylinder, x - cylinder.ref_x, y - cylinder.ref_y, nv, v);
        c = shade_lit(*light_, nv, v, rgb);
      } else {
        c = shade_pixel(lambert2[i], rgb[0], rgb[1], rgb[2]);
      }
      const size_t p = size_t(y) * width + size_t(x);
      uint8_t *out = rgba + 4 * p;
      if (!(nearer >> k & 1) && !(shaded_word(c) < frame_word(out))) continue;
      depth[p] = wz[i];
      out[0] = uint8_t(c), out[1] = uint8_t(c >> 8), out[2] = uint8_t(c >> 16), out[3] = 255;
      won_x0 = std::min(won_x0, x), won_x1 = std::max(won_x1, x);
      won_y0 = std::min(won_y0, y), won_y1 = std::max(won_y1, y);
    }
  }
  const PixelRect written{won_x0, won_y0, won_x1, won_y1};
  touched_.unite(written);
  if (!written.empty()) {
    // Nearby bonds (an atom's halves) propagate together: a pyramid level left above the depths
    // below it only makes covered() refine further, never changes its answer.
    PixelRect both = pending_;
    both.unite(written);
    if (both.x1 - both.x0 < kDeferExtent && both.y1 - both.y0 < kDeferExtent) {
      pending_ = both;
    } else {
      pyramid_.propagate(pending_);
      pending_ = written;
    }
  }
  return !written.empty();
}

void CpuSphereRaster::grow_cast_lists(int count) {
  const size_t n = size_t(count) * 2;  // room to grow
  cast_x_.resize(n), cast_y_.resize(n), cast_depth_.resize(n);
  cast_wz_.resize(n), cast_lambert2_.resize(n);
  cast_capacity_ = int(n);
}

}  // namespace lantern
