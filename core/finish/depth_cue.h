// Depth cueing of a composited band: a drawn pixel's colour fades linearly towards `color` with
// its distance from the eye (along the view axis), from none at `start` to all of it at `end`.
// The blend runs on the stored 8-bit sRGB-encoded values (as LAMMPS's depthcue does), so a pixel
// at fraction f becomes round(c + f (color - c)) per channel. Background pixels stay as they are.
//
// With `fade_alpha` (background: transparent and no depth_cue.color) there is no colour to fade
// towards, so the pixel fades out instead: its alpha becomes round(a (1 - f)) and its straight
// colour stays. Composited over any background B the pixel then shows (1 - f) c + f B where it
// was opaque: the same fog towards B that an opaque image with background B gets, whichever B the
// image is later placed on.
//
// Reads only the pixel's own distance; writes the colour of the band's owned rows. Needs no halo.
#pragma once

#include <cstdint>

#include "core/composite/row_bands.h"
#include "core/finish/view_positions.h"

namespace lantern {

struct DepthCueStyle {
  float start = 0.0f;            // distance of no fading, simulation units
  float end = 1.0f;              // distance of full fading; end <= start fades all beyond start
  uint8_t color[3] = {0, 0, 0};  // RGB8 faded towards
  bool fade_alpha = false;       // fade alpha towards 0 instead (transparent background)
};

// `vector`: with AVX2 where the processor has it, eight pixels at a time (the same bytes; false
// keeps to one at a time, for tests to compare). `threads`: how many threads (this one included)
// may share the rows; the same bytes at any count.
void apply_depth_cue(const ViewPositions &positions, const DepthCueStyle &style, BandFrame *band,
                     bool vector = true, int threads = 1);

}  // namespace lantern
