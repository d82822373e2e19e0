#include "core/view/view_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

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
