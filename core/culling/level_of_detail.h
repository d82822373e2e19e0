// Level of detail from brick prefixes (Rizzi et al. 2015, §3.5): since a brick's particles are in
// the z-order level layout, its first m particles are a spatially uniform sample of it. Two rules
// pick m per brick and the smaller wins:
//   - a budget (particles per frame) or a fraction, shared out in proportion to brick size;
//   - the screen-space rule: when the brick's particle spacing projects below `min_pixels`,
//     keep m = n (spacing_px / min_pixels)^3, so that the kept ones are min_pixels apart.
// Kept spheres grow so that the sample looks like the whole (LodGrowth). Approximate by design:
// never used by the exact modes unless configured.
//
// lod.select: nearest (opaque spheres) shares the frame's budget out by the particles each brick
// is expected to show (occlusion_estimate.h's coarse transmittance) instead of in proportion to
// size, and marks the bricks (VisibleBrick::nearest) whose `keep` particles gather() then picks
// from the brick's front (front_selection.h) at their own radius: in an opaque brick the dropped
// ones are behind them. A brick that is not opaque at that budget keeps the uniform prefix and
// the growth set here; one given under half its uniform share (expected hidden) does not grow.
#pragma once

#include <vector>

#include "core/bricks/brick_set.h"
#include "core/config/config.h"
#include "core/culling/visible_brick.h"
#include "core/view/view_geometry.h"

namespace lantern {

// How kept spheres grow when a brick keeps m of its n particles.
enum class LodGrowth {
  // By (n / m)^(1/3): the sample's volume stays the brick's (style: density, whose weights carry
  // the brightness and whose footprints only need to stay smooth).
  kVolume,
  // Opaque spheres. A brick whose spheres project under kCoveragePixels in radius grows them by
  // (n / m)^(1/2): m discs of the grown radius cover the projected area of the n, so a sparse
  // sub-pixel brick (gas, a cloud's outskirts) keeps the number of pixels it covers instead of
  // losing 1 - (m / n)^(1/3) of them (37 % at 25 %); a dense one covers its footprint either way.
  // Larger spheres grow by the cube root as before: their silhouettes are what one sees.
  kCoverage,
};
inline constexpr double kCoveragePixels = 1.0;

// Fills keep, radius_scale and nearest of every visible brick (keep = count when LOD is off).
// `nearest` allows lod.select: nearest (opaque spheres whose pass honours VisibleBrick::nearest).
// Returns whether any brick keeps less than all of its particles.
bool apply_level_of_detail(const LodConfig &lod, const BrickSet &set, const ViewGeometry &g,
                           LodGrowth growth, bool nearest, VisibleBricks *visible);

}  // namespace lantern
