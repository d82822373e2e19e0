// Outlines of a composited band: dark lines at silhouettes and depth jumps (the cross-sections
// paper's structure edges). A drawn pixel becomes `color` where some pixel within `width` pixels (a
// square neighbourhood) lies farther than it by more than `depth_threshold` x the sphere radius,
// the background counting as infinitely far. Spheres that intersect meet at continuous depth and so
// read as one structure; lines fall on the near side of each jump, `width` pixels thick.
//
// Reads only distances (view_positions.h), never colours, so it can run after another cue on
// the same band; writes the colour of the band's owned rows. Needs a halo of `width` rows.
#pragma once

#include <cstdint>

#include "core/composite/row_bands.h"
#include "core/finish/view_positions.h"

namespace lantern {

struct OutlineStyle {
  int width = 1;                 // pixels, >= 1
  float jump = 0.5f;             // depth jump that draws a line, simulation units
  uint8_t color[3] = {0, 0, 0};  // RGB8
};

// `vector`: with AVX2 where the processor has it, eight pixels at a time (the same bytes; false
// keeps to one at a time, for tests to compare). `threads`: how many threads (this one included)
// may share the rows; the same bytes at any count.
void draw_outlines(const ViewPositions &positions, const OutlineStyle &style, BandFrame *band,
                   bool vector = true, int threads = 1);

}  // namespace lantern
