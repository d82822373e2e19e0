#include "core/view/max_depth_pyramid.h"

#include <limits>

namespace lantern {
namespace {

// The largest depth of the (up to) 2 x 2 pixels of the finer level `z` (w x h) under tile (tx,
// ty) of the coarser one: fewer at the right and bottom edges of odd-sized levels, never none.
float max_of_children(const float *z, int w, int h, int tx, int ty) {
  float m = -std::numeric_limits<float>::infinity();
  for (int y = 2 * ty; y <= std::min(2 * ty + 1, h - 1); ++y)
    for (int x = 2 * tx; x <= std::min(2 * tx + 1, w - 1); ++x)
      m = std::max(m, z[size_t(y) * size_t(w) + size_t(x)]);
  return m;
}

}  // namespace

void MaxDepthPyramid::reset(const float *base, int w, int h, float fill) {
  base_ = base;
  if (levels_.empty()) levels_.resize(1);
  levels_[0].w = w, levels_[0].h = h;
  size_t k = 1;
  while (w > 1 || h > 1) {
    w = (w + 1) / 2, h = (h + 1) / 2;
    if (levels_.size() <= k) levels_.resize(k + 1);
    Level &l = levels_[k++];
    l.w = w, l.h = h;
    l.z.assign(size_t(w) * size_t(h), fill);
  }
  levels_.resize(k);
}

// Tiles of `level` overlapping the pixel rectangle [x0, x1] x [y0, y1] (level-0 pixels).
bool MaxDepthPyramid::covered_at(int level, int x0, int y0, int x1, int y1, float z) const {
  if (level == 0) {
    const int w = levels_[0].w;
    for (int y = y0; y <= y1; ++y) {
      const float *row = base_ + size_t(y) * size_t(w);
      for (int x = x0; x <= x1; ++x)
        if (!(row[x] < z)) return false;
    }
    return true;
  }
  const Level &l = levels_[size_t(level)];
  for (int ty = y0 >> level; ty <= (y1 >> level); ++ty)
    for (int tx = x0 >> level; tx <= (x1 >> level); ++tx) {
      if (l.z[size_t(ty) * l.w + tx] < z) continue;
      // Refine: this tile's pixels that lie inside the rectangle.
      const int px0 = std::max(x0, tx << level), px1 = std::min(x1, ((tx + 1) << level) - 1);
      const int py0 = std::max(y0, ty << level), py1 = std::min(y1, ((ty + 1) << level) - 1);
      if (!covered_at(level - 1, px0, py0, px1, py1, z)) return false;
    }
  return true;
}

void MaxDepthPyramid::propagate(const PixelRect &rect) {
  if (rect.empty()) return;
  for (size_t k = 1; k < levels_.size(); ++k) {
    const Level &below = levels_[k - 1];
    Level &l = levels_[k];
    const float *finer = level_data(k - 1);
    const int sh = int(k);
    bool changed = false;
    for (int ty = rect.y0 >> sh; ty <= (rect.y1 >> sh); ++ty)
      for (int tx = rect.x0 >> sh; tx <= (rect.x1 >> sh); ++tx) {
        const float m = max_of_children(finer, below.w, below.h, tx, ty);
        float &t = l.z[size_t(ty) * l.w + tx];
        changed |= m != t;
        t = m;
      }
    if (!changed) return;  // maxima only shrink: levels above cannot change either
  }
}

}  // namespace lantern
