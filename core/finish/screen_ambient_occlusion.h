// Screen-space ambient occlusion of a composited band (seed 004 section 7.1): each drawn pixel is
// darkened by how much of the hemisphere above it the surrounding composited surface covers.
//
// For a pixel at view-space point P with normal n (reconstructed from the depth of its
// neighbours, on each axis the side with the smaller depth step so that normals do not bend over
// silhouettes), `samples` pixels are read on a fixed golden-angle spiral of radius `radius`
// projected to pixels (at most kMaxAoPixels), turned by an angle that depends only on the
// pixel's image position (x mod 4, y mod 4): no random state, so every rank computes the same.
// A sample at view-space point Q occludes by max(0, cos(n, Q - P) - kAoBias) x
// max(0, 1 - |Q - P|^2 / radius^2); the colour is scaled by
// 1 - strength x min(1, 2 x mean occlusion). A convex surface (one lone sphere) never occludes
// itself: every chord points below its tangent plane.
//
// Reads only distances (view_positions.h); writes the colour of the band's owned rows. Needs a
// halo of kMaxAoPixels rows.
#pragma once

#include "core/composite/row_bands.h"
#include "core/finish/view_positions.h"

namespace lantern {

// The largest sampling radius in pixels, and so the halo of rows each band needs: bounds the
// work per pixel and the rows exchanged, whatever radius and zoom ask for.
inline constexpr int kMaxAoPixels = 32;
// Cosine below which a neighbour does not occlude: absorbs the error of normals reconstructed
// from 8-bit-free but float depth on curved surfaces.
inline constexpr float kAoBias = 0.1f;

struct AmbientOcclusionStyle {
  float radius = 1.0f;    // sampling radius, simulation units, > 0
  int samples = 16;       // 1..64
  float strength = 0.6f;  // [0, 1]
};

void apply_screen_ambient_occlusion(const ViewPositions &positions,
                                    const AmbientOcclusionStyle &style, BandFrame *band);

}  // namespace lantern
