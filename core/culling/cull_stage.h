// The culling stage for the OpenGL renderer: from the step's bricks to the list of particles to
// draw, for one scene. Brick-level work (frustum, cutting planes, level of detail, choosing the
// occlusion mode) is select_bricks (brick_selection.h); this class runs the per-particle
// occlusion traversal in the selected mode (occlusion_traversal.cpp): per-particle frustum and
// cuts in straddling bricks, hzb or nine-spheres occlusion, and the CPU point path for sub-pixel
// spheres. (With the CPU renderer, core/render/cpu_sphere_pass.h culls and draws in one pass.)
//
// Exact modes (frustum, cuts, occlusion none/hzb, no LOD, no point path) produce a list whose
// rendering is bit-identical to drawing every particle. Ownership: a Culler owns scratch buffers
// reused from frame to frame; it borrows the particles and bricks for one call.
// Thread-safety: one Culler per thread. hzb on images at least kTwoStripsFrom px wide runs on up
// to `threads` threads, one column strip each (column_strips.h), joined before cull() returns.
#pragma once

#include <string>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/common/page_allocator.h"
#include "core/config/config.h"
#include "core/culling/brick_selection.h"
#include "core/culling/column_strips.h"
#include "core/culling/cull_pass.h"
#include "core/culling/cull_settings.h"
#include "core/culling/cull_stats.h"
#include "core/culling/draw_list.h"
#include "core/culling/hzb.h"
#include "core/culling/nine_spheres.h"
#include "core/particles/particle_arrays.h"
#include "core/view/view_geometry.h"

namespace lantern {

class Culler {
 public:
  // Fills `out` with what to draw of `particles` (whose bricks are `bricks`) for a scene culled by
  // `settings` seen by `selection` (made by select_bricks for the same particles, bricks and
  // settings). Returns the selection's counts completed by the per-particle pass. `threads`: for
  // hzb's column strips (the list is the same at any count).
  CullStats cull(const ParticleArrays &particles, const BrickSet &bricks,
                 const CullSettings &settings, const BrickSelection &selection, DrawList *out,
                 int threads = 2);

  // select_bricks and cull in one call, the selection kept inside (tests and benchmarks).
  CullStats run(const ParticleArrays &particles, const BrickSet &bricks, const Camera &camera,
                const CullSettings &settings, const RadiusRule &radius, DrawList *out);
  // The double-precision camera of the last run() (the point path needs it after rendering).
  const ViewGeometry &geometry() const { return selection_.g; }
  // After cull() under hzb: true when every pixel of `rect` (clamped to the image) holds a sphere
  // it accepted - so one that is drawn - certainly nearer than view depth z. False in the other
  // modes. Bonds are culled with it after the spheres (core/culling/bond_selection.h).
  bool covered(const PixelRect &rect, double z) const;

 private:
  template <typename Positions, typename Radii>
  void process(const CullPass<Positions, Radii> &pass, const BrickSelection &sel, CullStats *st,
               DrawList *out);
  template <typename Positions, typename Radii>
  void process_strips(const CullPass<Positions, Radii> &pass, const BrickSelection &sel,
                      int threads, CullStats *st, DrawList *out);
  template <typename Positions, typename Radii>
  void process_sorted(const CullPass<Positions, Radii> &pass, const BrickSelection &sel,
                      CullStats *st, DrawList *out);
  bool occluded(OcclusionMode mode, const ViewGeometry &g, const Candidate &c, int strip);

  BrickSelection selection_;  // run()'s
  // hzb: one per column strip (one strip outside process_strips), and the strips' pyramids.
  std::vector<StripState> strips_ = std::vector<StripState>(1);
  std::vector<Hzb> hzb_ = std::vector<Hzb>(1);
  NineSpheresGrid nine_;
  bool nine_equivalent_ = false;  // nine-spheres compares equivalent radii, not world
  int hzb_strips_ = 0;            // the last cull()'s hzb pyramids: 0 (not hzb), else its strips
  PageVector<uint64_t> scratch_;
};

}  // namespace lantern
