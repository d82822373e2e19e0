// Level of detail from brick prefixes (seed 001 §3.5): since a brick's particles are in the
// z-order level layout, its first m particles are a spatially uniform sample of it. Two rules
// pick m per brick and the smaller wins:
//   - a budget (particles per frame) or a fraction, shared out in proportion to brick size;
//   - the screen-space rule: when the brick's particle spacing projects below `min_pixels`,
//     keep m = n (spacing_px / min_pixels)^3, so that the kept ones are min_pixels apart.
// Kept spheres grow by (n / m)^(1/3), which keeps the sample's covered volume (and so its look
// from afar) close to the full brick's. Approximate by design: never used by the exact modes
// unless configured.
#pragma once

#include <vector>

#include "core/bricks/brick_set.h"
#include "core/config/config.h"
#include "core/culling/visible_brick.h"
#include "core/view/view_geometry.h"

namespace lantern {

// Fills keep and radius_scale of every visible brick (keep = count when LOD is off). Returns
// whether any brick keeps less than all of its particles.
bool apply_level_of_detail(const LodConfig &lod, const BrickSet &set, const ViewGeometry &g,
                           std::vector<VisibleBrick> *visible);

}  // namespace lantern
