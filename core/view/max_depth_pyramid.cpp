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
    Level &l = levels_[k];
    l.w = w, l.h = h;
    if (k >= size_t(kFirstKeptLevel))
      l.z.assign(size_t(w) * size_t(h), fill);
    else
      PageVector<float>().swap(l.z);
    ++k;
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

float MaxDepthPyramid::block_max(int tx, int ty) const {
  const int w = levels_[0].w, h = levels_[0].h;
  const int x0 = tx << kFirstKeptLevel, y0 = ty << kFirstKeptLevel;
  const int y1 = std::min(y0 + 7, h - 1);
  const float *row = base_ + size_t(y0) * size_t(w);
#if defined(__SSE2__)
  if (x0 + 8 <= read_end_) {
    __m128 a = _mm_loadu_ps(row + x0), b = _mm_loadu_ps(row + x0 + 4);
    for (int y = y0 + 1; y <= y1; ++y) {
      row += w;
      a = _mm_max_ps(a, _mm_loadu_ps(row + x0));
      b = _mm_max_ps(b, _mm_loadu_ps(row + x0 + 4));
    }
    a = _mm_max_ps(a, b);
    a = _mm_max_ps(a, _mm_movehl_ps(a, a));
    return _mm_cvtss_f32(_mm_max_ss(a, _mm_shuffle_ps(a, a, 1)));
  }
#endif
  // The image's last columns (or no SSE): the pixels inside the image one by one, none from
  // read_end on (strips start at multiples of 64 columns, so no tile straddles one's end).
  const int x1 = std::min(x0 + 7, read_end_ - 1);
  float m = row[x0];
  for (int y = y0; y <= y1; ++y, row += w)
    for (int x = x0; x <= x1; ++x) m = std::max(m, row[x]);
  return m;
}

float MaxDepthPyramid::tile(int level, int tx, int ty) const {
  if (level == 0 || level >= kFirstKeptLevel)
    return level_data(size_t(level))[size_t(ty) * size_t(levels_[size_t(level)].w) + size_t(tx)];
  // A level that is not kept: the largest of its pixels.
  const int w = levels_[0].w, h = levels_[0].h;
  const int x0 = tx << level, y0 = ty << level;
  float m = base_[size_t(y0) * size_t(w) + size_t(x0)];
  for (int y = y0; y <= std::min(y0 + (1 << level) - 1, h - 1); ++y)
    for (int x = x0; x <= std::min(x0 + (1 << level) - 1, w - 1); ++x)
      m = std::max(m, base_[size_t(y) * size_t(w) + size_t(x)]);
  return m;
}

void MaxDepthPyramid::propagate(const PixelRect &rect) {
  if (rect.empty() || levels() < kFirstKeptLevel) return;
  {
    // Level 3 straight from level 0.
    Level &l = levels_[size_t(kFirstKeptLevel)];
    const int sh = kFirstKeptLevel;
    bool changed = false;
    for (int ty = rect.y0 >> sh; ty <= (rect.y1 >> sh); ++ty) {
      float *t = l.z.data() + size_t(ty) * size_t(l.w);
      for (int tx = rect.x0 >> sh; tx <= (rect.x1 >> sh); ++tx) {
        const float m = block_max(tx, ty);
        changed |= m != t[tx];
        t[tx] = m;
      }
    }
    if (!changed) return;
  }
  for (size_t k = kFirstKeptLevel + 1; k < levels_.size(); ++k) {
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
