#include "core/finish/depth_cue.h"

#include <algorithm>
#include <cmath>

namespace lantern {

namespace {

float fade_fraction(const DepthCueStyle &style, float z) {
  if (!(style.end > style.start)) return z > style.start ? 1.0f : 0.0f;
  return std::clamp((z - style.start) / (style.end - style.start), 0.0f, 1.0f);
}

}  // namespace

void apply_depth_cue(const ViewPositions &positions, const DepthCueStyle &style, BandFrame *band) {
  const int w = positions.width();
  for (int y = band->owned.y0; y < band->owned.y1; ++y) {
    uint8_t *rgba = &band->frame.rgba[size_t(y - band->first) * size_t(w) * 4];
    for (int x = 0; x < w; ++x) {
      const float z = positions.z(x, y);
      if (z == ViewPositions::kBackground) continue;
      const float f = fade_fraction(style, z);
      if (style.fade_alpha) {
        rgba[4 * x + 3] = uint8_t(float(rgba[4 * x + 3]) * (1.0f - f) + 0.5f);
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        const float from = rgba[4 * x + c];
        // Rounded to nearest: the blend lies in [0, 255].
        rgba[4 * x + c] = uint8_t(from + f * (float(style.color[c]) - from) + 0.5f);
      }
    }
  }
}

}  // namespace lantern
