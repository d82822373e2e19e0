#include "core/view/view_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/common/cpu_features.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_RECTS_AVX2 1
#include <immintrin.h>
#else
#define LANTERN_RECTS_AVX2 0
#endif

namespace lantern {
namespace {

#if LANTERN_RECTS_AVX2
// sphere_rect_tight of the perspective spheres a and b (x, y, z, r each), both beyond half the
// near plane: sphere_ndc's and ndc_rect_tight's operations lane by lane - lanes x and y of a, then
// of b - in the same order, so the same bits. (No FMA: the target is AVX2 alone, so nothing is
// contracted.)
__attribute__((target("avx2"))) void two_rects_avx2(const ViewGeometry &g, const double *a,
                                                    const double *b, double slack, PixelRect *out) {
  const double ra = a[3] + g.eps, rb = b[3] + g.eps, da = -a[2], db = -b[2];
  const __m256d xy = _mm256_setr_pd(a[0], a[1], b[0], b[1]);
  const __m256d d = _mm256_setr_pd(da, da, db, db), r = _mm256_setr_pd(ra, ra, rb, rb);
  const double dda = da * da - ra * ra, ddb = db * db - rb * rb;
  const __m256d dd = _mm256_setr_pd(dda, dda, ddb, ddb);
  const __m256d q = _mm256_add_pd(_mm256_mul_pd(xy, xy), dd);
  const __m256d root = _mm256_mul_pd(r, _mm256_sqrt_pd(_mm256_max_pd(_mm256_setzero_pd(), q)));
  const __m256d xd = _mm256_mul_pd(xy, d), scale = _mm256_setr_pd(g.sx, g.sy, g.sx, g.sy);
  const __m256d lo = _mm256_mul_pd(scale, _mm256_div_pd(_mm256_sub_pd(xd, root), dd));
  const __m256d hi = _mm256_mul_pd(scale, _mm256_div_pd(_mm256_add_pd(xd, root), dd));
  // pixels_of: x0 = first(x_lo), y0 = first(y_hi) and x1 = last(x_hi), y1 = last(y_lo), with
  // p = (x + 1) hw - 0.5 for x and (1 - y) hh - 0.5 = (-y + 1) hh - 0.5 for y (the same IEEE sum).
  const __m256d from_first = _mm256_blend_pd(lo, hi, 0xA), from_last = _mm256_blend_pd(hi, lo, 0xA);
  const __m256d negate_y = _mm256_setr_pd(0.0, -0.0, 0.0, -0.0), one = _mm256_set1_pd(1.0);
  const __m256d half = _mm256_set1_pd(0.5);
  const __m256d h = _mm256_setr_pd(0.5 * g.width, 0.5 * g.height, 0.5 * g.width, 0.5 * g.height);
  const auto pixel = [&](__m256d v) __attribute__((target("avx2"))) {
    return _mm256_sub_pd(_mm256_mul_pd(_mm256_add_pd(_mm256_xor_pd(v, negate_y), one), h), half);
  };
  const __m256d n = _mm256_setr_pd(g.width, g.height, g.width, g.height);
  const __m256d s = _mm256_set1_pd(slack), zero = _mm256_setzero_pd();
  // first: f = ceil(p - slack); f > 0 ? min(f, n) : 0 (a NaN f fails f > 0, as in the scalar).
  const __m256d f = _mm256_round_pd(_mm256_sub_pd(pixel(from_first), s),
                                    _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
  const __m256d first = _mm256_and_pd(_mm256_cmp_pd(f, zero, _CMP_GT_OQ), _mm256_min_pd(f, n));
  // last: f = floor(p + slack); f < n - 1 ? max(f, -1) : n - 1 (a NaN p gives a NaN f: n - 1).
  const __m256d n1 = _mm256_sub_pd(n, one);
  const __m256d l = _mm256_round_pd(_mm256_add_pd(pixel(from_last), s),
                                    _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  const __m256d last = _mm256_blendv_pd(n1, _mm256_max_pd(l, _mm256_set1_pd(-1.0)),
                                        _mm256_cmp_pd(l, n1, _CMP_LT_OQ));
  const __m128i x0y0 = _mm256_cvttpd_epi32(first), x1y1 = _mm256_cvttpd_epi32(last);
  _mm_storeu_si128(reinterpret_cast<__m128i *>(&out[0]), _mm_unpacklo_epi64(x0y0, x1y1));
  _mm_storeu_si128(reinterpret_cast<__m128i *>(&out[1]), _mm_unpackhi_epi64(x0y0, x1y1));
}
#endif

}  // namespace

void ViewGeometry::sphere_rects_tight(const double *spheres, size_t stride, int n, double slack,
                                      PixelRect *out) const {
  const auto one = [&](int k) {
    const double *s = spheres + size_t(k) * stride;
    out[k] = sphere_rect_tight({s[0], s[1], s[2]}, s[3], slack);
  };
  int k = 0;
#if LANTERN_RECTS_AVX2
  static_assert(sizeof(PixelRect) == 4 * sizeof(int32_t), "a rectangle is stored as 4 lanes");
  if (!orthographic && cpu_has_avx2()) {
    // A sphere reaching behind half the near plane gets the whole image (sphere_ndc's test).
    const auto beyond = [&](const double *s) {
      return !(-s[2] - (s[3] + eps) <= 0.5 * near_plane);
    };
    for (; k + 2 <= n; k += 2) {
      const double *a = spheres + size_t(k) * stride, *b = a + stride;
      if (beyond(a) && beyond(b)) {
        two_rects_avx2(*this, a, b, slack, out + k);
      } else {
        one(k), one(k + 1);
      }
    }
  }
#endif
  for (; k < n; ++k) one(k);
}

ViewGeometry ViewGeometry::from_camera(const Camera &camera, double scale) {
  ViewGeometry g;
  g.view = camera.view;
  g.orthographic = camera.orthographic;
  g.near_plane = camera.near_plane;
  g.far_plane = camera.far_plane;
  g.width = camera.width;
  g.height = camera.height;
  g.sx = camera.projection[0][0];
  g.sy = camera.projection[1][1];
  g.tx = camera.projection[3][0];
  g.ty = camera.projection[3][1];
  g.p22 = camera.projection[2][2];
  g.p32 = camera.projection[3][2];
  const double reach = scale + glm::length(camera.eye - camera.origin);
  g.eps = 1e-5 * reach;
  return g;
}

PixelRect ViewGeometry::ndc_rect(double x_lo, double x_hi, double y_lo, double y_hi) const {
  // Every centre in [lo, hi] plus a pixel of slack on each side. Hand-rolled floor/ceil: this
  // runs once per tested particle.
  const auto first = [](double p, int n) {  // floor(p) - 1, clamped to [0, n]
    if (!(p > 1.0)) return 0;               // NaN too: from the first pixel
    if (p >= double(n) + 1.0) return n;
    return int(p) - 1;
  };
  const auto last = [](double p, int n) {  // ceil(p) + 1, clamped to [-1, n - 1]
    if (p != p) return n - 1;
    if (p < -2.0) return -1;
    if (p >= double(n) - 2.0) return n - 1;
    const int t = int(p);  // p >= -2: truncation is ceil for p <= 0 and floor above
    return (p > 0.0 && p > double(t) ? t + 1 : t) + 1;
  };
  return pixels_of(x_lo, x_hi, y_lo, y_hi, first, last);
}

PixelRect ViewGeometry::sphere_rect(const glm::dvec3 &c, double radius) const {
  double x_lo, x_hi, y_lo, y_hi;
  if (!sphere_ndc(c, radius, &x_lo, &x_hi, &y_lo, &y_hi))
    return PixelRect{0, 0, width - 1, height - 1};
  return ndc_rect(x_lo, x_hi, y_lo, y_hi);
}

PixelRect ViewGeometry::box_rect(const glm::dvec3 corners[8]) const {
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 &p = corners[k];
    double x, y;
    if (orthographic) {
      x = sx * p.x + tx, y = sy * p.y + ty;
    } else {
      const double d = -p.z;
      if (d <= 0.5 * near_plane) return PixelRect{0, 0, width - 1, height - 1};
      x = sx * p.x / d, y = sy * p.y / d;
    }
    x_lo = std::min(x_lo, x), x_hi = std::max(x_hi, x);
    y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
  }
  return ndc_rect(x_lo, x_hi, y_lo, y_hi);
}

PixelRect ViewGeometry::box_rect(const glm::dvec3 &lo, const glm::dvec3 &hi) const {
  // Corner k is (k & 1 ? hi : lo).x, (k & 2 ? hi : lo).y, (k & 4 ? hi : lo).z: its projection
  // takes x from qx[k & 1][k >> 2] and y from qy[(k >> 1) & 1][k >> 2], each the very expression
  // box_rect evaluates, and they are taken in box_rect's order (min and max of a NaN depend on it).
  double qx[2][2], qy[2][2];
  const double xs[2] = {lo.x, hi.x}, ys[2] = {lo.y, hi.y};
  if (orthographic) {
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) qx[i][j] = sx * xs[i] + tx, qy[i][j] = sy * ys[i] + ty;
  } else {
    const double ds[2] = {-lo.z, -hi.z};
    if (ds[0] <= 0.5 * near_plane || ds[1] <= 0.5 * near_plane)
      return PixelRect{0, 0, width - 1, height - 1};
    if (std::isfinite(lo.x + lo.y + lo.z + hi.x + hi.y + hi.z)) {
      // Finite bounds: the extremes of the 8 quotients n / d are 4 of them. For d > 0, n / d is
      // non-decreasing in n, and in d non-increasing for n >= 0 and non-decreasing for n < 0
      // (IEEE multiplication and division round monotonically), so the least is the least
      // numerator over the far depth where it is >= 0, else over the near one - a quotient of
      // the 8, so the same bits up to the sign of a zero, which (x + 1) in ndc_rect drops.
      const double d_min = std::min(ds[0], ds[1]), d_max = std::max(ds[0], ds[1]);
      const double ax = sx * lo.x, bx = sx * hi.x, ay = sy * lo.y, by = sy * hi.y;
      const double nx_lo = std::min(ax, bx), nx_hi = std::max(ax, bx);
      const double ny_lo = std::min(ay, by), ny_hi = std::max(ay, by);
#if defined(__SSE2__)
      const __m128d n_lo = _mm_set_pd(ny_lo, nx_lo), n_hi = _mm_set_pd(ny_hi, nx_hi);
      const __m128d zero = _mm_setzero_pd(), near = _mm_set1_pd(d_min), far = _mm_set1_pd(d_max);
      const __m128d lo_far = _mm_cmpge_pd(n_lo, zero), hi_far = _mm_cmplt_pd(n_hi, zero);
      const __m128d q_lo =
          _mm_div_pd(n_lo, _mm_or_pd(_mm_and_pd(lo_far, far), _mm_andnot_pd(lo_far, near)));
      const __m128d q_hi =
          _mm_div_pd(n_hi, _mm_or_pd(_mm_and_pd(hi_far, far), _mm_andnot_pd(hi_far, near)));
      return ndc_rect(_mm_cvtsd_f64(q_lo), _mm_cvtsd_f64(q_hi),
                      _mm_cvtsd_f64(_mm_unpackhi_pd(q_lo, q_lo)),
                      _mm_cvtsd_f64(_mm_unpackhi_pd(q_hi, q_hi)));
#else
      return ndc_rect(nx_lo / (nx_lo >= 0.0 ? d_max : d_min), nx_hi / (nx_hi < 0.0 ? d_max : d_min),
                      ny_lo / (ny_lo >= 0.0 ? d_max : d_min),
                      ny_hi / (ny_hi < 0.0 ? d_max : d_min));
#endif
    }
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) qx[i][j] = sx * xs[i] / ds[j], qy[i][j] = sy * ys[i] / ds[j];
  }
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
  for (int k = 0; k < 8; ++k) {
    const double x = qx[k & 1][k >> 2], y = qy[(k >> 1) & 1][k >> 2];
    x_lo = std::min(x_lo, x), x_hi = std::max(x_hi, x);
    y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
  }
  return ndc_rect(x_lo, x_hi, y_lo, y_hi);
}

}  // namespace lantern
