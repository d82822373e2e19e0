#include "core/view/max_depth_pyramid.h"

#include <algorithm>
#include <cstddef>

namespace lantern {

void MaxDepthPyramid::reset(const float *base, int w, int h, float fill, int read_end) {
  base_ = base;
  read_end_ = read_end < 0 ? w : std::min(read_end, w);
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

// Tiles of `level` overlapping the pixel rectangle [x0, x1] x [y0, y1] (level-0 pixels). An
// inconclusive tile of level kScanFromLevel or below (8 x 8 pixels at most) is settled on level 0
// directly: one vector scan of its pixels costs less than walking the levels between.
bool MaxDepthPyramid::covered_at(int level, int x0, int y0, int x1, int y1, float z) const {
  if (level == 0) return covered_on_base(PixelRect{x0, y0, x1, y1}, z);
  const Level &l = levels_[size_t(level)];
  for (int ty = y0 >> level; ty <= (y1 >> level); ++ty) {
    const float *row = l.z.data() + size_t(ty) * size_t(l.w);
    for (int tx = x0 >> level; tx <= (x1 >> level); ++tx) {
      if (row[tx] < z) continue;
      // Refine: this tile's pixels that lie inside the rectangle.
      const int px0 = std::max(x0, tx << level), px1 = std::min(x1, ((tx + 1) << level) - 1);
      const int py0 = std::max(y0, ty << level), py1 = std::min(y1, ((ty + 1) << level) - 1);
      if (!covered_at(level <= kScanFromLevel ? 0 : level - 1, px0, py0, px1, py1, z)) return false;
    }
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
    const int tx0 = rect.x0 >> sh, tx1 = rect.x1 >> sh;
    bool changed = false;
    for (int ty = rect.y0 >> sh; ty <= (rect.y1 >> sh); ++ty) {
      // The two child rows (one at the bottom edge of an odd-height level), and the children's
      // second column clamped at the right edge: a pixel taken twice leaves the max unchanged.
      const float *r0 = finer + size_t(2 * ty) * size_t(below.w);
      const float *r1 = 2 * ty + 1 < below.h ? r0 + below.w : r0;
      float *t = l.z.data() + size_t(ty) * size_t(l.w);
      for (int tx = tx0; tx <= tx1; ++tx) {
        const int a = 2 * tx, b = std::min(a + 1, below.w - 1);
        const float m = std::max(std::max(r0[a], r0[b]), std::max(r1[a], r1[b]));
        changed |= m != t[tx];
        t[tx] = m;
      }
    }
    if (!changed) return;  // maxima only shrink: levels above cannot change either
  }
}

}  // namespace lantern
