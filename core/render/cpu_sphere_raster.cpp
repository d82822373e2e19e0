#include "core/render/cpu_sphere_raster.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lantern {
namespace {

constexpr uint32_t kNoParticle = std::numeric_limits<uint32_t>::max();
// Query depths are lowered by two float ulps below 1.0 before the strict comparison: the stored
// depths are double results rounded to float, so this keeps "covered" a guarantee.
constexpr double kQueryMargin = 2.0 * 5.96e-8;

uint8_t to_unorm8(double v) {
  return uint8_t(std::min(v, 1.0) * 255.0 + 0.5);
}

}  // namespace

void CpuSphereRaster::clear_target(const ViewGeometry &g, const uint8_t background[4], Frame *frame,
                                   std::vector<uint32_t> *owner) {
  // Also after a move (asynchronous writing takes the frame): sizes, not just the dimensions.
  const size_t pixels = size_t(g.width) * size_t(g.height);
  if (frame->width != g.width || frame->height != g.height || frame->depth.size() != pixels ||
      frame->rgba.size() != 4 * pixels)
    *frame = Frame(g.width, g.height);
  frame->clear(background);
  owner->assign(frame->pixel_count(), kNoParticle);
}

void CpuSphereRaster::begin_strip(const ViewGeometry &g, Frame *frame, std::vector<uint32_t> *owner,
                                  int x0, int x1) {
  g_ = g;
  frame_ = frame;
  owner_ = owner->data();
  x0_ = std::max(x0, 0), x1_ = std::min(x1, g.width - 1);
  int w = g.width, h = g.height;
  size_t k = 1;  // levels are kept between frames: refilled, not reallocated
  while (w > 1 || h > 1) {
    w = (w + 1) / 2, h = (h + 1) / 2;
    if (levels_.size() <= k) levels_.resize(k + 1);
    Level &l = levels_[k++];
    l.w = w, l.h = h;
    l.z.assign(size_t(w) * size_t(h), kBackgroundDepth);
  }
  levels_.resize(std::max<size_t>(k, 1));
  ray_x_.resize(size_t(g.width));
  ray_y_.resize(size_t(g.height));
  for (int x = 0; x < g.width; ++x) ray_x_[size_t(x)] = g.ray_x(x);
  for (int y = 0; y < g.height; ++y) ray_y_[size_t(y)] = g.ray_y(y);
}

bool CpuSphereRaster::covered(PixelRect rect, double z) const {
  rect.x0 = std::max(rect.x0, x0_), rect.x1 = std::min(rect.x1, x1_);
  if (rect.empty()) return true;
  if (!(z > g_.near_plane)) return false;
  const float zf = float(g_.window_depth(z) - kQueryMargin);
  const auto extent = unsigned(std::max(rect.x1 - rect.x0, rect.y1 - rect.y0));
  const int level = std::min(int(levels_.size()) - 1, extent == 0 ? 0 : 32 - __builtin_clz(extent));
  return covered_at(level, rect.x0, rect.y0, rect.x1, rect.y1, zf);
}

bool CpuSphereRaster::covered_at(int level, int x0, int y0, int x1, int y1, float z) const {
  if (level == 0) {
    for (int y = y0; y <= y1; ++y) {
      const float *row = frame_->depth.data() + size_t(y) * size_t(g_.width);
      for (int x = x0; x <= x1; ++x)
        if (!(row[x] < z)) return false;
    }
    return true;
  }
  const Level &l = levels_[size_t(level)];
  for (int ty = y0 >> level; ty <= (y1 >> level); ++ty)
    for (int tx = x0 >> level; tx <= (x1 >> level); ++tx) {
      if (l.z[size_t(ty) * l.w + tx] < z) continue;
      const int px0 = std::max(x0, tx << level), px1 = std::min(x1, ((tx + 1) << level) - 1);
      const int py0 = std::max(y0, ty << level), py1 = std::min(y1, ((ty + 1) << level) - 1);
      if (!covered_at(level - 1, px0, py0, px1, py1, z)) return false;
    }
  return true;
}

// Columns of row y whose centres may lie inside the silhouette: the analytic span, widened by a
// relative 1e-7 of a pixel against rounding; the per-pixel test decides. (Every drawing of a
// sphere goes through here, so whatever it decides at a boundary, it decides the same always.)
bool CpuSphereRaster::row_span(const glm::dvec3 &c, double r2, int y, const PixelRect &rect,
                               int *x0, int *x1) const {
  const double ry = ray_y_[size_t(y)];
  double lo, hi;
  if (g_.orthographic) {
    const double dy = c.y - ry, h2 = r2 - dy * dy;
    if (h2 <= 0.0) return false;
    const double h = std::sqrt(h2);
    lo = c.x - h, hi = c.x + h;
  } else {
    const double k = glm::dot(c, c) - r2, m = c.y * ry - c.z;
    const double a = k - c.x * c.x, b = -2.0 * c.x * m, cc = k * (ry * ry + 1.0) - m * m;
    if (a <= 0.0) {
      *x0 = rect.x0, *x1 = rect.x1;
      return true;
    }
    const double disc = b * b - 4.0 * a * cc;
    if (disc <= 0.0) return false;
    const double sq = std::sqrt(disc);
    lo = (-b - sq) / (2.0 * a), hi = (-b + sq) / (2.0 * a);
  }
  const double step = ray_x_.size() > 1 ? ray_x_[1] - ray_x_[0] : 1.0;
  const double f0 = std::ceil((lo - ray_x_[0]) / step - 1e-7),
               f1 = std::floor((hi - ray_x_[0]) / step + 1e-7);
  *x0 = int(std::max(f0, double(rect.x0)));
  *x1 = int(std::min(f1, double(rect.x1)));
  return *x0 <= *x1;
}

// The impostor shader's headlight: Lambert (light along the view ray) plus a Blinn-Phong
// highlight of exponent 40, clamped, to 8 bits.
void CpuSphereRaster::shade(size_t pixel, const uint8_t rgb[3], double lambert) {
  const double l2 = lambert * lambert, l4 = l2 * l2, l8 = l4 * l4, l32 = (l8 * l8) * (l8 * l8);
  const double diffuse = (0.2 + 0.8 * lambert) / 255.0, highlight = 0.3 * l32 * l8;
  uint8_t *out = frame_->rgba.data() + 4 * pixel;
  for (int k = 0; k < 3; ++k) out[k] = to_unorm8(rgb[k] * diffuse + highlight);
  out[3] = 255;
}

bool CpuSphereRaster::draw(const glm::dvec3 &c, double r, const uint8_t rgb[3], uint32_t index,
                           PixelRect rect) {
  rect.x0 = std::max(rect.x0, x0_), rect.x1 = std::min(rect.x1, x1_);
  if (rect.empty() || !(r > 0.0)) return false;
  const double r2 = r * r, c2 = glm::dot(c, c), d = -c.z;
  if (!g_.orthographic && c2 <= r2) return false;  // eye inside: the impostor draws nothing
  const double near = g_.near_plane, far = g_.far_plane, inv_r = 1.0 / r;
  const size_t width = size_t(g_.width);
  float *depth = frame_->depth.data();
  PixelRect written;
  for (int y = rect.y0; y <= rect.y1; ++y) {
    int xa, xb;
    if (!row_span(c, r2, y, rect, &xa, &xb)) continue;
    const double ry = ray_y_[size_t(y)];
    int wx0 = xb + 1, wx1 = xa - 1;
    const auto write = [&](int x, double hit_depth, double h) {
      if (hit_depth < near || hit_depth > far) return;  // the shader's clip-z discard
      const float wz = float(g_.window_depth(hit_depth));
      const size_t p = size_t(y) * width + size_t(x);
      if (wz > depth[p] || (wz == depth[p] && index >= owner_[p])) return;
      depth[p] = wz;
      owner_[p] = index;
      shade(p, rgb, h * inv_r);
      wx0 = std::min(wx0, x), wx1 = std::max(wx1, x);
    };
    if (g_.orthographic) {
      const double dy = c.y - ry, dy2 = dy * dy;
      for (int x = xa; x <= xb; ++x) {
        const double dx = c.x - ray_x_[size_t(x)], q2 = dx * dx + dy2;
        if (q2 >= r2) continue;
        const double h = std::sqrt(r2 - q2);
        write(x, d - h, h);
      }
    } else {
      // Unnormalised ray D = (rx, ry, -1), |D| = L: q^2 L^2 = |c|^2 L^2 - (c.D)^2, and the hit
      // lies h = sqrt(r^2 - q^2) before the closest approach; its view depth is t / L.
      const double l2_row = ry * ry + 1.0, m = c.y * ry - c.z;
      for (int x = xa; x <= xb; ++x) {
        const double rx = ray_x_[size_t(x)];
        const double l2 = rx * rx + l2_row, cd = c.x * rx + m;
        const double q2l2 = c2 * l2 - cd * cd;
        if (q2l2 >= r2 * l2) continue;
        const double inv = 1.0 / std::sqrt(l2);
        const double h = std::sqrt(r2 - q2l2 * inv * inv);
        write(x, (cd * inv - h) * inv, h);
      }
    }
    if (wx0 <= wx1) written.unite(PixelRect{wx0, y, wx1, y});
  }
  propagate(written);
  return !written.empty();
}

// Brings levels 1.. up to date over the level-0 pixels of `rect` (inside the strip).
void CpuSphereRaster::propagate(const PixelRect &rect) {
  if (rect.empty()) return;
  for (size_t k = 1; k < levels_.size(); ++k) {
    Level &l = levels_[k];
    const int sh = int(k);
    bool changed = false;
    for (int ty = rect.y0 >> sh; ty <= (rect.y1 >> sh); ++ty)
      for (int tx = rect.x0 >> sh; tx <= (rect.x1 >> sh); ++tx) {
        float m = -1.0f;
        if (k == 1) {
          for (int y = 2 * ty; y <= std::min(2 * ty + 1, g_.height - 1); ++y)
            for (int x = 2 * tx; x <= std::min(2 * tx + 1, g_.width - 1); ++x)
              m = std::max(m, frame_->depth[size_t(y) * size_t(g_.width) + size_t(x)]);
        } else {
          const Level &below = levels_[k - 1];
          for (int cy = 2 * ty; cy <= std::min(2 * ty + 1, below.h - 1); ++cy)
            for (int cx = 2 * tx; cx <= std::min(2 * tx + 1, below.w - 1); ++cx)
              m = std::max(m, below.z[size_t(cy) * below.w + cx]);
        }
        float &t = l.z[size_t(ty) * l.w + tx];
        changed |= m != t;
        t = m;
      }
    if (!changed) return;  // maxima only shrink: the levels above cannot change either
  }
}

}  // namespace lantern
