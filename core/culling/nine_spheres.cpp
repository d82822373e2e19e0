#include "core/culling/nine_spheres.h"

#include <algorithm>
#include <limits>

namespace lantern {

void NineSpheresGrid::reset(int width, int height) {
  w_ = width, h_ = height;
  const size_t n = size_t(width) * size_t(height);
  occupied_.assign(n, 0);
  neighbours_.assign(n, 0);
  depth_.assign(n, std::numeric_limits<float>::infinity());
  radius_.assign(n, std::numeric_limits<float>::infinity());
}

bool NineSpheresGrid::test_and_record(int x, int y, float d, float r) {
  if (x < 0 || y < 0 || x >= w_ || y >= h_) return false;
  const size_t i = size_t(y) * w_ + x;
  if (occupied_[i] && neighbours_[i] == 8) {
    bool hidden = true;
    for (int dy = -1; dy <= 1 && hidden; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const size_t j = size_t(y + dy) * w_ + (x + dx);  // N = 8: all neighbours exist
        if (!(depth_[j] <= d && radius_[j] >= r)) {
          hidden = false;
          break;
        }
      }
    if (hidden) return true;
  }
  if (!occupied_[i]) {
    occupied_[i] = 1;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = x + dx, ny = y + dy;
        if ((dx || dy) && nx >= 0 && ny >= 0 && nx < w_ && ny < h_)
          ++neighbours_[size_t(ny) * w_ + nx];
      }
  }
  depth_[i] = std::min(depth_[i], d);
  radius_[i] = std::min(radius_[i], r);
  return false;
}

}  // namespace lantern
