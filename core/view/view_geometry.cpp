#include "core/view/view_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lantern {

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
