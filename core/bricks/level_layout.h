// The z-order multi-level layout inside a brick (seed 001 §3.5, Fig. 3): the brick's particles,
// already in z-order, are re-laid so that level 0 (the first particle) comes first and each next
// level refines the previous one. We visit z-order positions in bit-reversed order (0, n/2, n/4,
// 3n/4, n/8, ...): at a level boundary this is exactly Fig. 3's layout, and inside a level the
// bit reversal spreads the partial level over the whole brick, so ANY prefix - not only whole
// levels - is a spatially uniform sample of the brick.
#pragma once

#include <cstdint>
#include <vector>

namespace lantern {

// Reorders `items[0, n)` (in z-order) into the level layout. `scratch` is reused between calls.
void apply_level_layout(uint32_t *items, uint32_t n, std::vector<uint32_t> *scratch);

// The z-order position (0-based) of the k-th item of the level layout of n items; exposed for
// tests. k < n.
uint32_t level_layout_source(uint32_t k, uint32_t n);

}  // namespace lantern
