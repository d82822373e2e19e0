// A brick that survived frustum and cut-plane culling, with what the later passes need: its
// screen footprint, nearest depth, the particle prefix level of detail keeps, and the radius to
// draw with. Plain value type.
#pragma once

#include <cstdint>

#include "core/common/page_allocator.h"
#include "core/culling/frustum.h"
#include "core/view/view_geometry.h"

namespace lantern {

struct VisibleBrick {
  uint32_t brick = 0;                              // index into BrickSet::bricks
  Containment containment = Containment::kInside;  // frustum: kStraddling tests each particle
  bool cut_each = false;      // some particle may lie on the dropped side of a cutting plane
  double near_depth = 0.0;    // nearest view depth any of its spheres can reach
  double radius = 0.0;        // largest (unscaled) radius of its particles
  PixelRect rect;             // pixels its spheres can touch
  uint32_t keep = 0;          // level of detail: draw the first `keep` particles of the brick
  bool nearest = false;       // level of detail: keep the brick's front if opaque (lod.select)
  float radius_scale = 1.0f;  // level of detail: radius growth that keeps the covered area
                              // (of the prefix; a brick drawn from its front keeps 1)
};

// A scene's visible bricks. Mapped pages from kPageBlockBytes on: growing the list in a scene's
// first frame (about 1 MiB at 10 M particles a rank) leaves no freed blocks in the heap.
using VisibleBricks = PageVector<VisibleBrick>;

}  // namespace lantern
