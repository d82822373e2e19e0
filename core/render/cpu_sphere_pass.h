// Culling and drawing in one pass for the CPU renderer: the visible bricks of a selection
// (core/culling/brick_selection.h) walked front to back in column strips (one thread each,
// core/culling/column_strips.h), every surviving particle ray-cast straight into the frame by
// the strip's CpuSphereRaster, and hzb occlusion tested against the same depth pyramid the raster
// draws into - so a hidden brick or particle costs one pyramid query and nothing else. Under
// occlusion `none` the same pass draws everything it gathers.
//
// Exact: the image is bit-identical to ray-casting every particle (cpu_sphere_raster.h explains
// why a skipped sphere could not have changed a bit). Sub-pixel spheres go to out->points when
// lod.point_path is on, for point_splats.h to draw afterwards.
// Ownership: owns its strips' rasters and buffers (reused between frames); borrows the frame,
// particles and bricks for one call. Thread-safety: one pass per thread; run() starts and joins its
// own helper threads (up to `threads` column strips, none narrower than kMinStripWidth px).
#pragma once

#include <cstdint>
#include <vector>

#include "core/bricks/brick_bonds.h"
#include "core/bricks/brick_set.h"
#include "core/common/page_allocator.h"
#include "core/config/config.h"
#include "core/culling/bond_selection.h"
#include "core/culling/brick_selection.h"
#include "core/culling/column_strips.h"
#include "core/culling/cull_settings.h"
#include "core/culling/cull_stats.h"
#include "core/culling/draw_list.h"
#include "core/culling/probabilistic/probabilistic_culler.h"
#include "core/particles/particle_arrays.h"
#include "core/render/bond_instances.h"
#include "core/render/cpu_sphere_raster.h"
#include "core/render/sphere_instances.h"
#include "core/view/frame.h"

namespace lantern {

// A scene's bonds for the CPU pass: the visible bond bricks (select_bond_bricks for the same
// selection) and their colors (whose recipe names the half-bonds and the box).
struct BondDrawing {
  const BondSelection *selection = nullptr;
  const BondRecipe *recipe = nullptr;
};

class CpuSpherePass {
 public:
  // Clears `frame` to `background` (RGBA8) and draws into it the particles of `selection`
  // (select_bricks for these particles, bricks and `cull`; its mode must be hzb, none or
  // probabilistic), colored by `recipe` and lit by `lighting`. `out` lists the spheres drawn (for
  // the counts) and the points left to splat. `step` keys probabilistic culling's random numbers.
  // `bonds` (or none): the half-bonds to draw too, brick by brick front to back with the spheres
  // in each strip, culled against the same depth (exactly, as the spheres are under hzb; not at all
  // under none). Returns the selection's counts completed by this pass. `threads`: column strips
  // drawn at once (the image and the lists are the same at any count).
  CullStats run(const ParticleArrays &particles, const BrickSet &bricks, const CullSettings &cull,
                const Lighting &lighting, const BrickSelection &selection,
                const InstanceRecipe &recipe, const uint8_t background[4], Frame *frame,
                DrawList *out, int64_t step = 0, int threads = 2,
                const BondDrawing *bonds = nullptr);

  // The meshlet classes of the last probabilistic run (tests).
  const ProbabilisticCuller &probabilistic() const { return probabilistic_; }

 private:
  // occlusion: probabilistic: Ibrahim et al.'s culling, then every particle of the potentially
  // visible set ray-cast exactly (no further occlusion test, so the culled share is the
  // method's own).
  CullStats run_probabilistic(const ParticleArrays &particles, const BrickSet &bricks,
                              const CullSettings &cull, const BrickSelection &selection,
                              const InstanceRecipe &recipe, const uint8_t background[4],
                              Frame *frame, DrawList *out, int64_t step, int threads);

  // Clears `frame` to `background` and gives the first `count` strips their rasters, begun on it.
  void begin_strips(int count, const ViewGeometry &g, const Lighting *lighting,
                    const uint8_t background[4], Frame *frame);
  // Ends every raster's strip (their depth pyramids are not kept between frames) and tells the
  // frame where they drew (Frame::drawn_within).
  void end_strips();
  // Strip k's half-bonds of visible bond bricks [from, to); marks those it drew in
  // bond_marks_[k] (one strip: counts them in bond_drawn_) and records the bricks' drops in
  // bond_drops_[k].
  template <typename Positions>
  void draw_bonds(int k, const Positions &pos, const ViewGeometry &g, const Frustum &frustum,
                  const CutPlanes &cuts, bool occlusion, const BondDrawing &bonds, size_t from,
                  size_t to);
  // The bond counts of the last run's first `count` strips.
  BondCounts count_bonds(const BondDrawing &bonds, int count);
  // Sizes the bond scratch for `count` strips of `bonds`.
  void begin_bonds(const BondDrawing &bonds, int count);

  ProbabilisticCuller probabilistic_;
  std::vector<StripState> strips_;
  std::vector<CpuSphereRaster> rasters_;
  std::vector<std::vector<PixelRect>> rects_;  // per strip: the rectangles of a bucket
  // Per strip: its half-bonds' drops, and per half-bond whether it drew it (one byte vector per
  // strip, so that the strips' threads never write the same memory). A single strip draws each
  // half at most once: it only counts them (bond_drawn_), with no marks.
  std::vector<BondDrops> bond_drops_;
  std::vector<std::vector<uint8_t>> bond_marks_;
  int64_t bond_drawn_ = 0;
  // From begin_strips to end_strips: the frame, what it was cleared to, the strips begun.
  Frame *frame_ = nullptr;
  uint8_t background_[4] = {0, 0, 0, 0};
  int strips_begun_ = 0;
  int bond_strips_ = 0;  // the strips of the last begin_bonds
  PageVector<uint64_t> scratch_;
};

// True when the CPU pass can render a selection in `mode`: hzb, probabilistic, or no culling.
inline bool cpu_pass_serves(OcclusionMode mode) {
  return mode == OcclusionMode::kHzb || mode == OcclusionMode::kNone ||
         mode == OcclusionMode::kProbabilistic;
}

}  // namespace lantern
