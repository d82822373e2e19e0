#include "core/finish/overlays/overlay_layout.h"

#include <algorithm>
#include <cmath>

namespace lantern {

OverlayLayout::OverlayLayout(int image_width, int image_height)
    : width_(image_width),
      height_(image_height),
      // 1.5% of the shorter side (15 pixels at 1024), at least 4.
      margin_(std::max(4, int(std::lround(0.015 * std::min(image_width, image_height))))) {}

std::array<int, 2> OverlayLayout::place(const OverlayPlace &place, int w, int h) {
  if (place.at) return *place.at;
  const int corner = int(place.corner);
  const bool right =
      place.corner == OverlayCorner::kTopRight || place.corner == OverlayCorner::kBottomRight;
  const bool bottom =
      place.corner == OverlayCorner::kBottomLeft || place.corner == OverlayCorner::kBottomRight;
  const int x = right ? width_ - margin_ - w : margin_;
  const int y = bottom ? height_ - margin_ - used_[corner] - h : margin_ + used_[corner];
  used_[corner] += h + margin_ / 2;
  return {x, y};
}

}  // namespace lantern
