// The particles of a density scene (`style: density`) splatted into this rank's DensityImage:
// the visible bricks of a selection, each brick's level-of-detail prefix (the first `keep`
// particles of its z-order level layout, core/bricks/level_layout.h), every kept particle
// weighted by count / keep so that the brick's total weight - its brightness - is preserved
// (Rizzi et al. 2015, §3.5, §4.2). Cutting planes drop particles by centre, as for spheres.
//
// How: without level of detail (every brick kept whole) the particles are read in published
// order, a sequential stream, and their footprints binned by image tile before they are
// deposited; with it, brick by brick (gathered with the next brick prefetched). Both give the
// sums of splatting each particle on its own: integers, so any order gives the same bits.
//
// The selection must come from select_density_bricks(): no frustum culling of bricks (a
// footprint reaches up to 1.5 px beyond its sphere, and only per-particle clipping is exact
// whatever the bricks, so the image cannot depend on the split), no occlusion (a sum has none).
// Ownership: borrows everything for the call. Thread-safety: none (writes the image).
#pragma once

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/config/config.h"
#include "core/culling/brick_selection.h"
#include "core/culling/cull_settings.h"
#include "core/culling/cull_stats.h"
#include "core/particles/particle_arrays.h"
#include "core/particles/radius_rule.h"
#include "core/render/density_splat.h"
#include "core/render/sphere_instances.h"

namespace lantern {

// select_bricks for a density scene: the scene's cutting planes and level of detail, every brick
// otherwise (frustum off, occlusion none, whatever `cull` says).
void select_density_bricks(const BrickSet &bricks, const Camera &camera, const CullSettings &cull,
                           const RadiusRule &radius, BrickSelection *out,
                           BrickCutCounts *cut_counts);

// The channels a density image of `coloring` needs: 1 (solid: one intensity) or 4.
int density_channels(ColorBy by);

// Resets `image` to the selection's size and `density_channels(recipe.coloring.by)` channels,
// then splats the kept particles, colored by `recipe`, dropping those beyond `cull`'s cutting
// planes in bricks the planes cut. Counts: drawn = particles splatted onto
// the image, lod_dropped, cut_culled (by particle), frustum_culled = centre behind the near
// plane or footprint wholly off the image. `pixels_written`, when given, receives the number of
// pixel updates (the benchmark's memory traffic).
CullStats render_density(const ParticleArrays &particles, const BrickSet &bricks,
                         const CullSettings &cull, const BrickSelection &selection,
                         const InstanceRecipe &recipe, DensityImage *image,
                         int64_t *pixels_written = nullptr);

}  // namespace lantern
