// The brick-level half of culling, for one scene and frame: which bricks the camera can see
// (frustum and cutting planes, per brick), their screen footprints, how much of each level of
// detail keeps, and which occlusion mode will judge their particles (resolving `auto`).
//
// What it produces feeds either per-particle pass: the culler's (core/culling/cull_stage.h, for
// OpenGL) or the CPU sphere pass (core/render/cpu_sphere_pass.h); the pipeline picks the renderer
// from the selection's occlusion mode. Ownership: a BrickSelection owns its vectors (reused from
// frame to frame); it refers to bricks by index. Thread-safety: none.
#pragma once

#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/config/config.h"
#include "core/culling/brick_cut_counts.h"
#include "core/culling/cull_settings.h"
#include "core/culling/cull_stats.h"
#include "core/culling/visible_brick.h"
#include "core/particles/particle_arrays.h"
#include "core/particles/radius_rule.h"
#include "core/view/view_geometry.h"

namespace lantern {

struct BrickSelection {
  ViewGeometry g;         // the double-precision camera of this frame
  VisibleBricks visible;  // front to back unless the mode is none (as configured)
  OcclusionMode mode = OcclusionMode::kNone;  // resolved: never kAuto
  RadiusRule radius;                          // the scene's radius rule
  bool reduced = false;                       // level of detail keeps less than some brick holds
  CullStats stats;  // so far: candidates, brick counts, brick-level frustum / cut drops, mode
};

// Classifies `bricks` for a scene culled by `cull`, whose spheres follow `radius`, seen by
// `camera` into *out.
void select_bricks(const BrickSet &bricks, const Camera &camera, const CullSettings &cull,
                   const RadiusRule &radius, BrickSelection *out);

// The same, with the cutting planes judged through `cut_counts` (kept by the caller between
// frames, one per scene; null: none): updated to the scene's planes first, so a plane edit since
// the last frame reclassifies only the bricks it touches. The selection is identical to the one
// above.
void select_bricks(const BrickSet &bricks, const Camera &camera, const CullSettings &cull,
                   const RadiusRule &radius, BrickSelection *out, BrickCutCounts *cut_counts);

}  // namespace lantern
