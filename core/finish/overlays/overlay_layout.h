// Where overlays go on the image: a box of w x h pixels at a corner (inside a margin) or at an
// explicit top-left pixel. Overlays sharing a corner stack away from it (top corners downwards,
// bottom corners upwards) in the order they are placed, so several labels in one corner do not
// overlap. One per image and frame; not thread-safe.
#pragma once

#include <array>

#include "core/config/config.h"

namespace lantern {

class OverlayLayout {
 public:
  OverlayLayout(int image_width, int image_height);
  // The top-left pixel of a w x h box at `place`, and (corners) reserves it.
  std::array<int, 2> place(const OverlayPlace &place, int w, int h);
  int margin() const { return margin_; }

 private:
  int width_, height_, margin_;
  std::array<int, 4> used_{};  // per corner: pixels taken so far along the stacking direction
};

}  // namespace lantern
