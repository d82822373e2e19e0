#include "core/culling/hzb.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/common/cpu_features.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_HZB_AVX2 1
#include <immintrin.h>
#else
#define LANTERN_HZB_AVX2 0
#endif

namespace lantern {
namespace {

constexpr float kUncovered = std::numeric_limits<float>::infinity();

// Window depths the GPU computes in float (matrix product, divide, z * 0.5 + 0.5) can be off by a
// few float ulps near 1.0; with a tiny near plane (camera inside the particles) that is more than
// the length tolerance buys. Stored and queried depths keep this many units apart on top.
constexpr double kUlpBelowOne = 5.96e-8;  // 2^-24: a float ulp in [0.5, 1), larger than below
constexpr double kWindowMargin = 8.0 * kUlpBelowOne;
// Stored depths are rounded to float to nearest (at most half an ulp down), so they get half an
// ulp more margin instead of a nextafter per pixel.
constexpr double kStoreMargin = kWindowMargin + 0.5 * kUlpBelowOne;

// One row of a perspective occluder (add_occluder's per-pixel loop), its inputs fixed per row.
struct OccluderRow {
  double c2, cx, l2_row, m, r2, r_in2, z_lo, z_hi, eps;
};

#if LANTERN_HZB_AVX2
// Columns [x, x + 4 * count) of `row`: add_occluder's perspective loop four columns at a time, its
// operations lane by lane in the same order (no FMA: the target is AVX2 alone, so nothing is
// contracted), so the same depths are stored. Why: a pixel costs two square roots and two
// divisions, and the divider takes four lanes about as fast as one; hzb culling of a 1 M-atom fcc
// frame at 1024^2 spent most of its time here. Widens [*wx0, *wx1] to the columns written.
__attribute__((target("avx2"))) void occluder_columns_avx2(const ViewGeometry &g,
                                                           const OccluderRow &o,
                                                           const double *ray_x, float *row, int x,
                                                           int count, int *wx0, int *wx1) {
  const __m256d c2 = _mm256_set1_pd(o.c2), cx = _mm256_set1_pd(o.cx);
  const __m256d l2_row = _mm256_set1_pd(o.l2_row), m = _mm256_set1_pd(o.m);
  const __m256d r2 = _mm256_set1_pd(o.r2), r_in2 = _mm256_set1_pd(o.r_in2);
  const __m256d z_lo = _mm256_set1_pd(o.z_lo), z_hi = _mm256_set1_pd(o.z_hi);
  const __m256d eps = _mm256_set1_pd(o.eps), one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5);
  const __m256d minus_p22 = _mm256_set1_pd(-g.p22), p32 = _mm256_set1_pd(g.p32);
  const __m256d margin = _mm256_set1_pd(kStoreMargin);
  const __m256i low_halves = _mm256_setr_epi32(0, 2, 4, 6, 0, 0, 0, 0);
  for (int k = 0; k < count; ++k, x += 4) {
    const __m256d rx = _mm256_loadu_pd(ray_x + x);
    const __m256d l2 = _mm256_add_pd(_mm256_mul_pd(rx, rx), l2_row);
    const __m256d cd = _mm256_add_pd(_mm256_mul_pd(cx, rx), m);
    const __m256d q2l2 = _mm256_sub_pd(_mm256_mul_pd(c2, l2), _mm256_mul_pd(cd, cd));
    // Skipped where q2l2 >= r_in2 l2 (a NaN compares false there: not skipped, as in the loop).
    const __m256d inside = _mm256_cmp_pd(q2l2, _mm256_mul_pd(r_in2, l2), _CMP_NGE_UQ);
    const __m256d inv = _mm256_div_pd(one, _mm256_sqrt_pd(l2));
    const __m256d root =
        _mm256_sqrt_pd(_mm256_sub_pd(r2, _mm256_mul_pd(_mm256_mul_pd(q2l2, inv), inv)));
    const __m256d depth = _mm256_mul_pd(_mm256_sub_pd(_mm256_mul_pd(cd, inv), root), inv);
    // Skipped where depth < z_lo or depth > z_hi (the shader would discard it).
    const __m256d clipped = _mm256_or_pd(_mm256_cmp_pd(depth, z_lo, _CMP_LT_OQ),
                                         _mm256_cmp_pd(depth, z_hi, _CMP_GT_OQ));
    const __m256d keep = _mm256_andnot_pd(clipped, inside);
    // window_depth(depth + eps) + kStoreMargin, to float.
    const __m256d d = _mm256_add_pd(depth, eps);
    const __m256d z_ndc = _mm256_div_pd(_mm256_add_pd(_mm256_mul_pd(minus_p22, d), p32), d);
    const __m128 v =
        _mm256_cvtpd_ps(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(half, z_ndc), half), margin));
    const __m128 keep4 =
        _mm256_castps256_ps128(_mm256_permutevar8x32_ps(_mm256_castpd_ps(keep), low_halves));
    const __m128 old = _mm_loadu_ps(row + x);
    const __m128 write = _mm_and_ps(keep4, _mm_cmplt_ps(v, old));
    const int bits = _mm_movemask_ps(write);
    if (!bits) continue;
    _mm_storeu_ps(row + x, _mm_blendv_ps(old, v, write));
    *wx0 = std::min(*wx0, x + __builtin_ctz(unsigned(bits)));
    *wx1 = std::max(*wx1, x + 31 - __builtin_clz(unsigned(bits)));
  }
}
#endif

}  // namespace

std::atomic<bool> &Hzb::vector_rows() {
  static std::atomic<bool> on{true};
  return on;
}

void Hzb::reset(const ViewGeometry &g) {
  g_ = g;
  depth_.assign(size_t(g.width) * size_t(g.height), kUncovered);
  pyramid_.reset(depth_.data(), g.width, g.height, kUncovered);
  rays_.reset(g);
}

bool Hzb::covered(const PixelRect &rect, double z) const {
  if (rect.empty()) return true;
  if (!(z > g_.near_plane)) return false;  // reaches the near plane: never provably hidden
  // Rounded to nearest, the float is at most half an ulp above: take that off as well.
  return pyramid_.covered(rect, float(g_.window_depth(z) - kStoreMargin));
}

bool Hzb::usable(const glm::dvec3 &c, double r) const {
  const double eps = g_.eps, d = -c.z;
  if (g_.orthographic) {
    // The quad lies at depth d - r; it must sit strictly between the planes.
    return d - r >= g_.near_plane * 1.0001 + eps && d - r <= g_.far_plane - eps;
  }
  const double dist = glm::length(c);
  if (dist <= r + eps) return false;  // eye inside (or nearly): the shader draws nothing
  // The vertex shader places a square at distance t = dist - r along w = c / dist (unless the
  // near plane clamps it), of half-size s. Its corners' depths lie within t w_z -+ sqrt(2) s
  // sqrt(1 - w_z^2); the square must not be clipped by the near or far plane.
  const double t = dist - r;
  if (t < g_.near_plane * 1.0001 + eps) return false;
  const double s = t * r / std::sqrt(dist * dist - r * r);
  const double wz = d / dist;
  const double spread = std::sqrt(2.0) * s * std::sqrt(std::max(0.0, 1.0 - wz * wz));
  return t * wz - spread >= g_.near_plane * 1.0001 + eps && t * wz + spread <= g_.far_plane - eps;
}

bool Hzb::add_occluder(const glm::dvec3 &c, double r, const PixelRect &rect) {
  const double eps = g_.eps;
  const double r_in = r - eps;  // pixel centres closer than this to the axis are certainly inside
  if (r_in <= 0.0 || rect.empty() || !usable(c, r)) return false;
  const double r2 = r * r, r_in2 = r_in * r_in, c2 = glm::dot(c, c);
  const double z_lo = g_.near_plane + eps, z_hi = g_.far_plane - eps;
  const double d = -c.z;
  PixelRect written;
  const double *ray_x = rays_.x_data();
  const bool vector = vector_rows().load(std::memory_order_relaxed) && cpu_has_avx2();
  for (int y = rect.y0; y <= rect.y1; ++y) {
    int xa, xb;
    // Columns whose centres may lie inside the circle of radius r_in, with a pixel of slack each
    // side; exactness comes from the per-pixel test that follows.
    if (!rays_.row_span(c, r_in2, y, rect.x0, rect.x1, 2.0, &xa, &xb)) continue;
    const double ry = rays_.y(y);
    float *row = depth_.data() + size_t(y) * size_t(g_.width);
    int wx0 = xb + 1, wx1 = xa - 1;  // columns written in this row
    if (g_.orthographic) {
      const double dy = c.y - ry, dy2 = dy * dy;
      for (int x = xa; x <= xb; ++x) {
        const double dx = c.x - ray_x[x], q2 = dx * dx + dy2;
        if (q2 >= r_in2) continue;
        const double depth = d - std::sqrt(r2 - q2);
        if (depth < z_lo || depth > z_hi) continue;  // the shader would discard it (clip z)
        const float v = float(g_.window_depth(depth + eps) + kStoreMargin);
        if (v < row[x]) row[x] = v, wx0 = std::min(wx0, x), wx1 = std::max(wx1, x);
      }
    } else {
      // Unnormalised ray D = (rx, ry, -1), |D| = L: b = c.D / L, q^2 = |c|^2 - b^2 (no harmful
      // cancellation in double), hit view depth = (b - sqrt(r^2 - q^2)) / L.
      const double l2_row = ry * ry + 1.0, m = c.y * ry - c.z;
      int x = xa;
#if LANTERN_HZB_AVX2
      // Whole groups of four columns in vectors (only [xa, xb] is read and written: the strip's
      // own columns), the rest below.
      if (vector) {
        const OccluderRow o{c2, c.x, l2_row, m, r2, r_in2, z_lo, z_hi, eps};
        const int groups = (xb - xa + 1) / 4;
        occluder_columns_avx2(g_, o, ray_x, row, xa, groups, &wx0, &wx1);
        x += 4 * groups;
      }
#endif
      for (; x <= xb; ++x) {
        const double rx = ray_x[x];
        const double l2 = rx * rx + l2_row, cd = c.x * rx + m;
        const double q2l2 = c2 * l2 - cd * cd;
        if (q2l2 >= r_in2 * l2) continue;
        const double inv = 1.0 / std::sqrt(l2);
        const double depth = (cd * inv - std::sqrt(r2 - q2l2 * inv * inv)) * inv;
        if (depth < z_lo || depth > z_hi) continue;  // the shader would discard it (clip z)
        const float v = float(g_.window_depth(depth + eps) + kStoreMargin);
        if (v < row[x]) row[x] = v, wx0 = std::min(wx0, x), wx1 = std::max(wx1, x);
      }
    }
    if (wx0 <= wx1) written.unite(PixelRect{wx0, y, wx1, y});
  }
  pyramid_.propagate(written);
  return true;
}

}  // namespace lantern
