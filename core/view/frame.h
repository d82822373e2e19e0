// One rendered image with per-pixel depth: what a rank renders, what compositing merges, and what
// the output stage writes.
//
// Layout: row-major, row 0 is the TOP of the image (as image files store it). color is RGBA8,
// 4 bytes per pixel; depth is the OpenGL window depth in [0, 1] (0 = near plane), with exactly
// 1.0f (kBackgroundDepth) where nothing was drawn. Window depth is monotonic in distance for both
// projections, so "nearer" is "smaller" everywhere. Ownership: a Frame owns its buffers.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

#include "core/common/page_allocator.h"

namespace lantern {

inline constexpr float kBackgroundDepth = 1.0f;

// What a renderer that drew a frame right after clear() says of it: every pixel outside the
// rectangle [x0, x1) x [y0, y1) (y counted from the top row) still holds what that clear() wrote,
// `background` at kBackgroundDepth.
struct DrawnWithin {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  uint8_t background[4] = {0, 0, 0, 0};
};

struct Frame {
  int width = 0;
  int height = 0;
  PageVector<uint8_t> rgba;  // 4 * width * height
  PageVector<float> depth;   // width * height
  // Set by the CPU raster's pass (cpu_sphere_pass.h) once it has drawn; compositing's scan then
  // reads only that rectangle of the frame, and drops it (its merges write outside it). clear()
  // and reset() drop it, and so does whoever draws into the frame without widening it.
  std::optional<DrawnWithin> drawn_within;

  Frame() = default;
  Frame(int w, int h) : width(w), height(h), rgba(size_t(w) * h * 4), depth(size_t(w) * h) {}

  // Makes this what Frame(w, h) makes (zero colour and depth), reusing the buffers when they
  // already have the size: the buffers are mapped pages (page_allocator.h), so a frame made anew
  // every step would fault all of them in again.
  void reset(int w, int h) {
    const size_t pixels = size_t(w) * size_t(h);
    if (rgba.size() != 4 * pixels || depth.size() != pixels) {
      *this = Frame(w, h);
      return;
    }
    width = w, height = h;
    drawn_within.reset();
    std::fill(rgba.begin(), rgba.end(), uint8_t(0));
    std::fill(depth.begin(), depth.end(), 0.0f);
  }

  // The same as reset(w, h) then clear(background_rgba), without zeroing the buffers first.
  void reset(int w, int h, const uint8_t background_rgba[4]) {
    const size_t pixels = size_t(w) * size_t(h);
    if (rgba.size() != 4 * pixels || depth.size() != pixels)
      *this = Frame(w, h);
    else
      width = w, height = h;
    clear(background_rgba);
  }

  size_t pixel_count() const { return size_t(width) * size_t(height); }
  size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }

  // Fills every pixel with the background color (RGBA8) at background depth.
  void clear(const uint8_t background_rgba[4]) {
    drawn_within.reset();
    uint32_t packed;  // one 4-byte store per pixel: this runs for every frame
    std::memcpy(&packed, background_rgba, 4);
    uint8_t *out = rgba.data();
    for (size_t i = 0; i < pixel_count(); ++i) std::memcpy(out + 4 * i, &packed, 4);
    depth.assign(pixel_count(), kBackgroundDepth);
  }
};

}  // namespace lantern
