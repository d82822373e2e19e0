#include "core/culling/hzb.h"

#include <cmath>
#include <limits>

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

}  // namespace

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
      for (int x = xa; x <= xb; ++x) {
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
