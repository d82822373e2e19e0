#include "core/culling/view_geometry.h"

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
  // Pixel column x is sampled at NDC (x + 0.5) / W * 2 - 1; keep every centre in [lo, hi] plus a
  // pixel of slack on each side.
  const auto col = [&](double ndc) { return (ndc + 1.0) * 0.5 * width - 0.5; };
  const auto row = [&](double ndc) { return (1.0 - ndc) * 0.5 * height - 0.5; };
  PixelRect r;
  const double fx0 = std::floor(col(x_lo)) - 1, fx1 = std::ceil(col(x_hi)) + 1;
  const double fy0 = std::floor(row(y_hi)) - 1, fy1 = std::ceil(row(y_lo)) + 1;
  if (!(fx0 <= fx1) || !(fy0 <= fy1)) return PixelRect{0, 0, width - 1, height - 1};  // NaN: all
  r.x0 = int(std::max(fx0, 0.0));
  r.x1 = int(std::min(fx1, double(width - 1)));
  r.y0 = int(std::max(fy0, 0.0));
  r.y1 = int(std::min(fy1, double(height - 1)));
  return r;
}

PixelRect ViewGeometry::sphere_rect(const glm::dvec3 &c, double radius) const {
  const double r = radius + eps;
  const PixelRect full{0, 0, width - 1, height - 1};
  if (orthographic)
    return ndc_rect(sx * (c.x - r) + tx, sx * (c.x + r) + tx, sy * (c.y - r) + ty,
                    sy * (c.y + r) + ty);
  const double d = -c.z;
  if (d - r <= 0.5 * near_plane) return full;
  // Tangent lines from the eye to the circle in the xz (yz) plane: slopes m = x / d with
  // m^2 (d^2 - r^2) - 2 x d m + x^2 - r^2 = 0.
  const double dd = d * d - r * r;
  const auto slopes = [&](double x, double *lo, double *hi) {
    const double root = r * std::sqrt(std::max(x * x + dd, 0.0));
    *lo = (x * d - root) / dd;
    *hi = (x * d + root) / dd;
  };
  double mx0, mx1, my0, my1;
  slopes(c.x, &mx0, &mx1);
  slopes(c.y, &my0, &my1);
  return ndc_rect(sx * mx0, sx * mx1, sy * my0, sy * my1);
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

}  // namespace lantern
