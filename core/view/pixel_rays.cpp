#include "core/view/pixel_rays.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace lantern {

void PixelRays::reset(const ViewGeometry &g) {
  orthographic_ = g.orthographic;
  width_ = g.width;
  x_.resize(size_t(g.width + kPadding));
  y_.resize(size_t(g.height + kPadding));
  for (int c = 0; c < g.width + kPadding; ++c) x_[size_t(c)] = g.ray_x(c);
  for (int r = 0; r < g.height + kPadding; ++r) y_[size_t(r)] = g.ray_y(r);
}

bool PixelRays::row_span(const glm::dvec3 &c, double r2, int row, int lo, int hi, double widen,
                         int *x0, int *x1) const {
  const double ry = y_[size_t(row)];
  double a_lo, a_hi;  // ray x range
  if (orthographic_) {
    const double dy = c.y - ry, h2 = r2 - dy * dy;
    if (h2 <= 0.0) return false;
    const double h = std::sqrt(h2);
    a_lo = c.x - h, a_hi = c.x + h;
  } else {
    // q^2 < r^2  <=>  K (rx^2 + ry^2 + 1) - (cx rx + m)^2 < 0, K = |c|^2 - r^2, m = cy ry - cz.
    const double k = glm::dot(c, c) - r2, m = c.y * ry - c.z;
    const double a = k - c.x * c.x, b = -2.0 * c.x * m, cc = k * (ry * ry + 1.0) - m * m;
    if (a <= 0.0) {  // degenerate (sphere around the eye plane): the whole row
      *x0 = lo, *x1 = hi;
      return lo <= hi;
    }
    const double disc = b * b - 4.0 * a * cc;
    if (disc <= 0.0) return false;
    const double sq = std::sqrt(disc);
    a_lo = (-b - sq) / (2.0 * a), a_hi = (-b + sq) / (2.0 * a);
  }
  // ray_x is affine in the column: ray_x(x) = ray_x(0) + x * step.
  const double step = x_[1] - x_[0];
  const double f0 = std::ceil((a_lo - x_[0]) / step - widen),
               f1 = std::floor((a_hi - x_[0]) / step + widen);
  // NaN where the squares above overflow (view-space lengths beyond about 1e77; the camera takes
  // positions up to 1e150): no span, as for a row the sphere misses. The callers write occluders,
  // so a span left out only culls less. Both ends clamped on both sides before the conversion:
  // a finite f0 or f1 may lie far beyond int's range.
  if (std::isnan(f0) || std::isnan(f1)) return false;
  *x0 = int(std::clamp(f0, double(lo), double(hi) + 1.0));
  *x1 = int(std::clamp(f1, double(lo) - 1.0, double(hi)));
  return *x0 <= *x1;
}

}  // namespace lantern
