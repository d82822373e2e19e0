// Depth cueing of a composited band: a drawn pixel's colour fades linearly towards `color` with
// its distance from the eye (along the view axis), from none at `start` to all of it at `end`.
// The blend runs on the stored 8-bit sRGB-encoded values (as LAMMPS's depthcue does), so a pixel
// at fraction f becomes round(c + f (color - c)) per channel. Background pixels stay as they are.
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
};

void apply_depth_cue(const ViewPositions &positions, const DepthCueStyle &style, BandFrame *band);

}  // namespace lantern
