#include "core/culling/hzb.h"

#include <cmath>
#include <limits>

namespace lantern {
namespace {

constexpr float kUncovered = std::numeric_limits<float>::infinity();

// The smallest float >= v (stored depths must never round towards the eye).
float float_up(double v) {
  float f = float(v);
  if (double(f) < v) f = std::nextafter(f, kUncovered);
  return f;
}
// The largest float <= v.
float float_down(double v) {
  float f = float(v);
  if (double(f) > v) f = std::nextafter(f, -kUncovered);
  return f;
}

// Window depths the GPU computes in float (matrix product, divide, z * 0.5 + 0.5) can be off by a
// few float ulps near 1.0; with a tiny near plane (camera inside the particles) that is more than
// the length tolerance buys. Stored and queried depths keep this many units apart on top.
constexpr double kWindowMargin = 8.0 * 5.96e-8;

}  // namespace

void Hzb::reset(const ViewGeometry &g) {
  g_ = g;
  int w = g.width, h = g.height;
  levels_.resize(1);
  for (;;) {
    Level &l = levels_.back();
    l.w = w, l.h = h;
    l.z.assign(size_t(w) * size_t(h), kUncovered);
    if (w == 1 && h == 1) break;
    w = (w + 1) / 2, h = (h + 1) / 2;
    levels_.emplace_back();
  }
  dirty_ = PixelRect{};
}

bool Hzb::covered(const PixelRect &rect, double z) const {
  if (rect.empty()) return true;
  if (!(z > g_.near_plane)) return false;  // reaches the near plane: never provably hidden
  const float zf = float_down(g_.window_depth(z) - kWindowMargin);
  int level = 0;
  while (level + 1 < int(levels_.size()) && ((rect.x1 >> level) - (rect.x0 >> level) > 1 ||
                                             (rect.y1 >> level) - (rect.y0 >> level) > 1))
    ++level;
  return covered_at(level, rect.x0, rect.y0, rect.x1, rect.y1, zf);
}

// Tiles of `level` overlapping the pixel rectangle [x0, x1] x [y0, y1] (level-0 pixels).
bool Hzb::covered_at(int level, int x0, int y0, int x1, int y1, float z) const {
  const Level &l = levels_[size_t(level)];
  for (int ty = y0 >> level; ty <= (y1 >> level); ++ty)
    for (int tx = x0 >> level; tx <= (x1 >> level); ++tx) {
      if (l.z[size_t(ty) * l.w + tx] < z) continue;
      if (level == 0) return false;
      // Refine: this tile's pixels that lie inside the rectangle.
      const int px0 = std::max(x0, tx << level), px1 = std::min(x1, ((tx + 1) << level) - 1);
      const int py0 = std::max(y0, ty << level), py1 = std::min(y1, ((ty + 1) << level) - 1);
      if (!covered_at(level - 1, px0, py0, px1, py1, z)) return false;
    }
  return true;
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
  const double r2 = r * r, r_in2 = r_in * r_in;
  const double z_lo = g_.near_plane + eps, z_hi = g_.far_plane - eps;
  Level &l0 = levels_[0];
  const double d = -c.z;
  for (int y = rect.y0; y <= rect.y1; ++y) {
    const double ry = g_.ray_y(y);
    float *row = l0.z.data() + size_t(y) * l0.w;
    for (int x = rect.x0; x <= rect.x1; ++x) {
      const double rx = g_.ray_x(x);
      double depth;
      if (g_.orthographic) {
        const double dx = c.x - rx, dy = c.y - ry;
        const double q2 = dx * dx + dy * dy;
        if (q2 >= r_in2) continue;
        depth = d - std::sqrt(r2 - q2);
      } else {
        const double inv = 1.0 / std::sqrt(rx * rx + ry * ry + 1.0);
        const glm::dvec3 dir{rx * inv, ry * inv, -inv};
        const double b = glm::dot(c, dir);
        const glm::dvec3 q = c - b * dir;
        const double q2 = glm::dot(q, q);
        if (q2 >= r_in2) continue;
        depth = (b - std::sqrt(r2 - q2)) * inv;  // view depth of the hit: t * (-dir.z)
      }
      if (depth < z_lo || depth > z_hi) continue;  // the shader would discard it (clip z)
      const float v = float_up(g_.window_depth(depth + eps) + kWindowMargin);
      if (v < row[x]) row[x] = v;
    }
  }
  dirty_.unite(rect);
  return true;
}

void Hzb::refresh() {
  if (dirty_.empty()) return;
  for (size_t k = 1; k < levels_.size(); ++k) {
    const Level &below = levels_[k - 1];
    Level &l = levels_[k];
    const int sh = int(k);
    for (int ty = dirty_.y0 >> sh; ty <= (dirty_.y1 >> sh); ++ty)
      for (int tx = dirty_.x0 >> sh; tx <= (dirty_.x1 >> sh); ++tx) {
        float m = -kUncovered;
        for (int cy = 2 * ty; cy <= std::min(2 * ty + 1, below.h - 1); ++cy)
          for (int cx = 2 * tx; cx <= std::min(2 * tx + 1, below.w - 1); ++cx)
            m = std::max(m, below.z[size_t(cy) * below.w + cx]);
        l.z[size_t(ty) * l.w + tx] = m;
      }
  }
  dirty_ = PixelRect{};
}

}  // namespace lantern
