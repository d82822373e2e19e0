#include "core/render/cpu_sphere_raster.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/culling/max_depth_tile.h"

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
  rays_.reset(g);
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
    // The analytic span, widened by 1e-7 px against rounding; the per-pixel test decides.
    // (Every drawing of a sphere goes through here, so a boundary pixel is decided alike always.)
    if (!rays_.row_span(c, r2, y, rect.x0, rect.x1, 1e-7, &xa, &xb)) continue;
    const double ry = rays_.y(y);
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
        const double dx = c.x - rays_.x(x), q2 = dx * dx + dy2;
        if (q2 >= r2) continue;
        const double h = std::sqrt(r2 - q2);
        write(x, d - h, h);
      }
    } else {
      // Unnormalised ray D = (rx, ry, -1), |D| = L: q^2 L^2 = |c|^2 L^2 - (c.D)^2, and the hit
      // lies h = sqrt(r^2 - q^2) before the closest approach; its view depth is t / L.
      const double l2_row = ry * ry + 1.0, m = c.y * ry - c.z;
      for (int x = xa; x <= xb; ++x) {
        const double rx = rays_.x(x);
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
        const float m =
            k == 1 ? max_of_children(frame_->depth.data(), g_.width, g_.height, tx, ty, -1.0f)
                   : max_of_children(levels_[k - 1].z.data(), levels_[k - 1].w, levels_[k - 1].h,
                                     tx, ty, -1.0f);
        float &t = l.z[size_t(ty) * l.w + tx];
        changed |= m != t;
        t = m;
      }
    if (!changed) return;  // maxima only shrink: the levels above cannot change either
  }
}

}  // namespace lantern
