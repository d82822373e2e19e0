// One sphere scene drawn on this rank, exactly as the pipeline draws it: the visible bricks
// (frustum, cutting planes, level of detail, the occlusion mode), the renderer decided once
// (renderer_choice.h), culling and drawing - the CPU sphere pass, or the culler then OpenGL's
// impostors - with the scene's bonds, and the point path's splats. Tests and benchmarks draw
// through this function too, so they exercise the pipeline's own wiring instead of copies of it.
//
// Local: no communication; the frame is this rank's, before compositing. Ownership: a RankScene
// borrows everything it points to for the call; the scratch is reused between calls (keep one
// per thread). Thread-safety: one call at a time per scratch (and per renderer).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/bricks/brick_bonds.h"
#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/common/status.h"
#include "core/culling/bond_selection.h"
#include "core/culling/brick_cut_counts.h"
#include "core/culling/brick_selection.h"
#include "core/culling/cull_stage.h"
#include "core/culling/cull_stats.h"
#include "core/culling/draw_list.h"
#include "core/particles/bond_arrays.h"
#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"
#include "core/particles/periodic_box.h"
#include "core/particles/radius_rule.h"
#include "core/pipeline/scene_settings.h"
#include "core/render/cpu_sphere_pass.h"
#include "core/render/gl/sphere_renderer.h"
#include "core/render/object_occlusion.h"
#include "core/view/frame.h"

namespace lantern {

// What to draw, and with what.
struct RankScene {
  const ParticleArrays *particles = nullptr;
  const BrickSet *bricks = nullptr;  // of `particles`
  const Camera *camera = nullptr;    // at the frame's size (the sample frame's with samples > 1)
  SceneSettings settings;            // the scene's, resolved from its configuration
  RadiusRule radius;                 // the scene's radius rule for these particles
  Extent global;     // the step's extent over every rank: automatic color ranges, max radius
  int64_t step = 0;  // keys probabilistic culling's random numbers
  SphereRenderer *renderer = nullptr;          // null: no OpenGL, the CPU raster draws
  const OcclusionVolume *occlusion = nullptr;  // object-space ambient occlusion, or none
  BrickCutCounts *cut_counts = nullptr;        // the scene's, kept between frames, or none
  // The published bonds and their half-bonds for `bricks` (brick_bonds.h), drawn when the
  // scene's settings.cull.bonds says so; `box` gives their minimum image (or none).
  const BondArrays *bonds = nullptr;
  const BrickBonds *bond_halves = nullptr;
  const PeriodicBox *box = nullptr;
  // Threads for the CPU raster's and the hzb culler's column strips (the image and the counts
  // are the same at any count; the pipeline passes `threads:`).
  int threads = 2;

  RankScene() = default;
  RankScene(const ParticleArrays &p, const BrickSet &b, const Camera &c, SceneSettings s,
            const RadiusRule &r)
      : particles(&p), bricks(&b), camera(&c), settings(std::move(s)), radius(r) {}
  // The common case of tests: `scene` resolved, its radius rule, no global extent, no OpenGL.
  RankScene(const ParticleArrays &p, const BrickSet &b, const Camera &c, const SceneConfig &scene)
      : RankScene(p, b, c, scene_settings(scene), radius_rule(scene, p)) {}
};

// The buffers a rank draws with, kept between scenes and steps.
struct RankDrawScratch {
  BrickSelection selection;  // the visible bricks of the scene being drawn (read it afterwards)
  Culler culler;             // per-particle culling for OpenGL (pyramids, grids reused)
  CpuSpherePass cpu_pass;    // culling and drawing in one pass for the CPU renderer
  DrawList draw;             // the CPU pass's drawn spheres stay; the rest is released once drawn
  std::vector<SphereInstance> instances;  // OpenGL's instances of the drawn spheres
  BondSelection bond_selection;           // the visible bricks' half-bonds
  std::vector<uint32_t> bond_kept;        // OpenGL: the half-bonds to draw
  std::vector<BondInstance> bond_instances;
};

// What one rank drew and how long each part took (milliseconds).
struct RankDraw {
  CullStats cull;        // this rank's counts, and the occlusion mode run (and why)
  std::string renderer;  // "cpu" (CPU raster) or "opengl"
  double cull_ms = 0;    // brick selection and culling (with the CPU pass: drawing too)
  double instances_ms = 0, draw_ms = 0, readback_ms = 0;
};

// Clears *frame to the scene's background at the camera's size and draws the scene into it.
// Returns OK, or OpenGL's failure (the frame is then incomplete; *out is filled either way).
Status draw_scene_on_rank(const RankScene &scene, RankDrawScratch *scratch, Frame *frame,
                          RankDraw *out);

}  // namespace lantern
