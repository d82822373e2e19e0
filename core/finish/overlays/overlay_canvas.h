// Drawing on the finished image (rank 0): coverage masks, rectangles and antialiased lines,
// blended over the pixels in 8-bit integer arithmetic (the same bytes on every machine).
//
// A pixel of colour d under colour c at coverage a (0..255) becomes (c a + d (255 - a) + 127) /
// 255 per channel; its alpha a_d becomes a_d + a (255 - a_d) / 255 (so an opaque image stays
// opaque, a transparent background takes the overlay's partial coverage). A pixel that is not
// opaque (background: transparent) holds straight colour, so there d counts with its alpha:
// (c a 255 + d a_d (255 - a)) / (a 255 + a_d (255 - a)) - text over nothing keeps its own colour
// and its antialiased edges carry partial alpha. Everything is clipped to the image. Pure
// functions on the Frame passed in.
#pragma once

#include <cstdint>
#include <functional>

#include "core/color/colormap.h"
#include "core/finish/overlays/font_face.h"
#include "core/view/frame.h"

namespace lantern {

// Blends `color` over pixel (x, y) at coverage 0..255; outside the image nothing happens.
void blend_pixel(Frame *image, int x, int y, const Rgb8 &color, uint8_t coverage);

// The text mask with its top-left corner at (x, y).
void draw_mask(Frame *image, const TextMask &mask, int x, int y, const Rgb8 &color);

// The rectangle [x, x + w) x [y, y + h), fully covered.
void fill_rect(Frame *image, int x, int y, int w, int h, const Rgb8 &color);

// A point of a line in image pixels (x right, y down; pixel (i, j) spans [i, i+1) x [j, j+1))
// with the window depth of the line there (0 near .. 1 far).
struct LinePoint {
  double x = 0, y = 0, depth = 0;
};

// A line `width` pixels wide from a to b, antialiased by each pixel centre's distance to the
// segment (coverage 1 within width / 2 - 0.5, falling to 0 at width / 2 + 0.5). With
// `depth_test`, a pixel whose composited depth is nearer than the line's depth there (linear
// between a and b: window depth is affine in screen space) keeps its colour.
void draw_line(Frame *image, const LinePoint &a, const LinePoint &b, double width,
               const Rgb8 &color, bool depth_test);

}  // namespace lantern
