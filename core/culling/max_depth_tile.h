// One step of a max-depth pyramid (hzb.h, cpu_sphere_raster.h): the largest depth of the 2 x 2
// cells of a finer level under a tile of the coarser one (fewer at the right and bottom edges of
// odd-sized levels).
#pragma once

#include <algorithm>
#include <cstddef>

namespace lantern {

// `z`: the finer level, w x h, row-major. (tx, ty): the tile of the coarser level. `floor`: the
// result when every child is below it (a value below any depth).
inline float max_of_children(const float *z, int w, int h, int tx, int ty, float floor) {
  float m = floor;
  for (int y = 2 * ty; y <= std::min(2 * ty + 1, h - 1); ++y)
    for (int x = 2 * tx; x <= std::min(2 * tx + 1, w - 1); ++x)
      m = std::max(m, z[size_t(y) * size_t(w) + size_t(x)]);
  return m;
}

}  // namespace lantern
