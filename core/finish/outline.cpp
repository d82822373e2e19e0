#include "core/finish/outline.h"

#include <algorithm>
#include <vector>

namespace lantern {

void draw_outlines(const ViewPositions &positions, const OutlineStyle &style, BandFrame *band) {
  const int w = positions.width(), first = positions.first_row(), last = positions.last_row();
  const int reach = style.width;
  // The farthest distance within `reach` columns, for every held row; then the farthest of those
  // within `reach` rows: the square neighbourhood's maximum in O(reach) per pixel.
  std::vector<float> row_max(size_t(last - first) * size_t(w));
  for (int y = first; y < last; ++y) {
    float *out = &row_max[size_t(y - first) * size_t(w)];
    for (int x = 0; x < w; ++x) {
      float m = positions.z(x, y);
      const int x1 = std::min(w - 1, x + reach);
      for (int k = std::max(0, x - reach); k <= x1; ++k) m = std::max(m, positions.z(k, y));
      out[x] = m;
    }
  }
  for (int y = band->owned.y0; y < band->owned.y1; ++y) {
    const int y0 = std::max(first, y - reach), y1 = std::min(last - 1, y + reach);
    uint8_t *rgba = &band->frame.rgba[size_t(y - first) * size_t(w) * 4];
    for (int x = 0; x < w; ++x) {
      const float z = positions.z(x, y);
      if (z == ViewPositions::kBackground) continue;
      float far = z;
      for (int k = y0; k <= y1; ++k)
        far = std::max(far, row_max[size_t(k - first) * size_t(w) + x]);
      if (far - z > style.jump) std::copy(style.color, style.color + 3, rgba + 4 * size_t(x));
    }
  }
}

}  // namespace lantern
