// A max-depth pyramid over a depth image: level k holds, per tile of 2^k x 2^k pixels, the
// largest depth of the tile's pixels. It answers "does every pixel of this rectangle hold a depth
// strictly below z?" touching at most 2 x 2 tiles of the level whose tiles are as wide as the
// rectangle, refining only where a tile is inconclusive (small tiles straight on level 0), after
// probes of the rectangle's centre pixel and then of its corners and edge middles. Every answer is
// the definition's (a test scans the image to check), so how it is reached changes no culling
// decision. Used by the hzb occlusion test (core/culling/hzb.h, over its own conservative depth
// image) and by the CPU sphere raster (core/render/cpu_sphere_raster.h, over the frame's depth).
//
// Ownership: level 0 is borrowed (the caller's depth image, valid until the next reset); levels
// 3.. are owned (1 and 2 are not kept: kFirstKeptLevel) and kept between resets (refilled, not
// reallocated) until release(); the larger levels are mapped pages, so that release() hands them
// back to the system (lazily: core/common/page_allocator.h). Thread-safety: none; one thread writes
// and reads a pyramid (two threads may each own a pyramid over disjoint column strips of one
// image). Units: whatever depth the caller stores (window depth in Lantern).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

#include "core/common/page_allocator.h"
#include "core/view/view_geometry.h"

namespace lantern {

class MaxDepthPyramid {
 public:
  // Builds levels 1.. over the w x h row-major image `base`, every tile set to `fill` (the
  // depth `base` holds everywhere at this point). `read_end`: no column of `base` from this one
  // on is read (default w): a pyramid over a strip of columns that other threads write beside it
  // (column_strips.h) passes its strip's end, so that a vector read past a rectangle's right
  // edge, its extra lanes dropped, never reads a column another thread writes.
  void reset(const float *base, int w, int h, float fill, int read_end = -1);

  // True if every pixel of `rect` (inside the image, or empty) holds a depth strictly below z.
  bool covered(const PixelRect &rect, float z) const {
    if (rect.empty()) return true;
    // The rectangle's centre pixel first: a sphere or box that shows anywhere mostly shows
    // there (it is tested nearest first), and one load answers "no" without the descent.
    const int cx = (rect.x0 + rect.x1) >> 1, cy = (rect.y0 + rect.y1) >> 1;
    const size_t w = size_t(levels_[0].w);
    if (!(base_[size_t(cy) * w + size_t(cx)] < z)) return false;
    // Then the rectangle's corners and the middles of its edges, together (no early exit): a
    // bond or sphere that shows but not at its centre mostly shows at one of them, while a
    // hidden one pays only eight loads of pixels the descent reads again (on the bonded-network
    // bench, tests/bench/lammps_dump_image_bonds.sh, they answer about 65 % of the queries that
    // pass the centre but are not covered).
    const float *top = base_ + size_t(rect.y0) * w, *mid = base_ + size_t(cy) * w;
    const float *bottom = base_ + size_t(rect.y1) * w;
    const bool rim = (top[rect.x0] < z) & (top[cx] < z) & (top[rect.x1] < z) & (mid[rect.x0] < z) &
                     (mid[rect.x1] < z) & (bottom[rect.x0] < z) & (bottom[cx] < z) &
                     (bottom[rect.x1] < z);
    if (!rim) return false;
    // A rectangle of at most 8 x 8 pixels is scanned on level 0 (the levels that would answer it
    // are not kept: kFirstKeptLevel).
    const auto extent = unsigned(std::max(rect.x1 - rect.x0, rect.y1 - rect.y0));
    if (extent < (1u << kFirstKeptLevel)) return covered_on_base(rect, z);
    // The level whose tiles are at least as wide as the rectangle: it spans at most 2 x 2 of them.
    const int level = std::min(levels(), 32 - __builtin_clz(extent));
    return covered_at(level, rect.x0, rect.y0, rect.x1, rect.y1, z);
  }

  // The same answer read on level 0 alone, a row at a time, for a non-empty `rect` inside the
  // image. A rectangle at most 8 pixels wide whose rows have 8 readable pixels from x0 on (a
  // sphere's or a small box's) takes two 4-wide compares a row, the lanes past x1 dropped. For a
  // sphere of a few pixels that costs fewer loads and branches than covered()'s descent: on the
  // 1 M-atom LJ frame (tests/bench/lammps_dump_image.sh) the descent read about 3 tiles and
  // scanned 2 of them on level 0 per sphere, after its nine probes.
  bool covered_on_base(const PixelRect &rect, float z) const;

  // Brings the levels above 0 up to date after the caller lowered depths inside `rect`.
  void propagate(const PixelRect &rect);

  // The number of levels above level 0.
  int levels() const { return int(levels_.size()) - 1; }

  // What tile (tx, ty) of `level` holds (level 0: the pixel; levels 1 and 2, which are not kept,
  // worked out from level 0), and the level's size in tiles; for tests of propagate(). After a
  // propagate() over every lowered pixel, a tile holds the largest of its 2 x 2 children (the
  // ones inside the level below).
  float tile(int level, int tx, int ty) const;
  int level_width(int level) const { return levels_[size_t(level)].w; }
  int level_height(int level) const { return levels_[size_t(level)].h; }

  // Frees the levels (a pyramid kept between frames costs a 63rd of its image's depth); the next
  // reset() makes them again. covered() and propagate() need a reset() first.
  void release() {
    std::vector<Level>().swap(levels_);
    base_ = nullptr;
  }

 private:
  struct Level {
    int w = 0, h = 0;
    PageVector<float> z;  // levels 0 to 2: empty (the borrowed base is read instead)
  };
  // Tiles of levels up to this one (8 x 8 pixels) are refined on level 0 at once.
  static constexpr int kScanFromLevel = 3;
  // The lowest level above 0 that is stored and kept up to date. Levels 1 and 2 would only ever
  // be read by rectangles of at most 8 x 8 pixels, which covered() scans on level 0 at once, or
  // by refinement, which goes from level kScanFromLevel straight to level 0; so propagate()
  // brings level 3 up straight from level 0 (eight rows of eight pixels a tile, two vector
  // maxima a row) instead of through two levels of 2 x 2 maxima one tile at a time.
  static constexpr int kFirstKeptLevel = kScanFromLevel;
  static_assert(kFirstKeptLevel == 3, "propagate() reads level-0 blocks of 8 x 8 pixels");
  // Level 3's tile (tx, ty): the largest depth of its pixels inside the image.
  float block_max(int tx, int ty) const;
  bool covered_at(int level, int x0, int y0, int x1, int y1, float z) const;
  const float *level_data(size_t k) const { return k == 0 ? base_ : levels_[k].z.data(); }

  const float *base_ = nullptr;
  int read_end_ = 0;  // reset()'s read_end
  std::vector<Level> levels_;
};

inline bool MaxDepthPyramid::covered_on_base(const PixelRect &rect, float z) const {
  const size_t w = size_t(levels_[0].w);
#if defined(__SSE2__)
  if (rect.x1 - rect.x0 < 8 && rect.x0 + 8 <= read_end_) {
    const int inside = (1 << (rect.x1 - rect.x0 + 1)) - 1;
    const __m128 zz = _mm_set1_ps(z);
    for (int y = rect.y0; y <= rect.y1; ++y) {
      const float *row = base_ + size_t(y) * w + size_t(rect.x0);
      const int above = _mm_movemask_ps(_mm_cmpnlt_ps(_mm_loadu_ps(row), zz)) |
                        _mm_movemask_ps(_mm_cmpnlt_ps(_mm_loadu_ps(row + 4), zz)) << 4;
      if (above & inside) return false;
    }
    return true;
  }
#endif
  // A row's loop has no early exit, so the compiler turns it into vector compares.
  for (int y = rect.y0; y <= rect.y1; ++y) {
    const float *row = base_ + size_t(y) * w;
    int above = 0;
    for (int x = rect.x0; x <= rect.x1; ++x) above |= !(row[x] < z);
    if (above) return false;
  }
  return true;
}

}  // namespace lantern
