// The stage between camera and rendering: from the step's bricks to the list of particles to
// draw, for one scene. Frustum and cut-plane culling of bricks (per particle only in bricks that
// straddle), level of detail from brick prefixes, occlusion culling in the configured mode, and
// the CPU point path for sub-pixel spheres.
//
// Exact modes (frustum, cuts, occlusion none/hzb, no LOD, no point path) produce a list whose
// rendering is bit-identical to drawing every particle. Ownership: a Culler owns scratch buffers
// reused from frame to frame; it borrows the particles and bricks for one call.
// Thread-safety: one Culler per thread. hzb on images at least 256 px wide runs on two threads
// (the caller's and one helper, joined before run() returns), one strip of columns each.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/config/config.h"
#include "core/culling/cut_planes.h"
#include "core/culling/draw_list.h"
#include "core/culling/frustum.h"
#include "core/culling/hzb.h"
#include "core/culling/nine_spheres.h"
#include "core/view/view_geometry.h"
#include "core/culling/visible_brick.h"
#include "core/particles/particle_arrays.h"
#include "core/render/cpu_sphere_raster.h"

namespace lantern {

// Where the CPU raster draws when the culler chooses it (scene.renderer, see config.h): the
// scene's frame, a per-pixel owner buffer, the background and each particle's colour.
struct RasterTarget {
  Frame *frame = nullptr;
  std::vector<uint32_t> *owner = nullptr;
  uint8_t background[4] = {255, 255, 255, 255};
  std::function<void(int64_t index, uint8_t rgb[3])> colour;
};

struct CullStats {
  std::string occlusion;  // the mode run; for auto also why, e.g. "hzb (auto: dense, ...)"
  std::string renderer = "opengl";  // "cpu" when the CPU raster drew during culling
  int64_t candidates = 0;           // finite particles of the rank
  int64_t frustum_culled = 0;       // outside the view frustum
  int64_t cut_culled = 0;           // on the dropped side of a cutting plane
  int64_t lod_dropped = 0;          // left out by level of detail
  int64_t occlusion_culled = 0;     // hidden (hzb: provably; nine_spheres: by the rule)
  int64_t drawn = 0;                // impostors sent to the GPU
  int64_t splatted = 0;             // CPU point path
  int64_t bricks = 0, bricks_outside = 0, bricks_inside = 0, bricks_occluded = 0;
  bool per_particle_frustum = false;  // some brick straddled the frustum
  double ms = 0.0;
};

class Culler {
 public:
  // Fills `out` with what to draw of `particles` (whose bricks are `bricks`) for `scene` seen by
  // `camera`. `scene.culling.occlusion` may be overridden with `mode` (the benchmark does).
  // With a `raster` target, the culler draws the survivors itself on the CPU when the occlusion
  // mode it runs is hzb or none (then out->rasterized is set and the target's frame holds the
  // image); nine_spheres modes still leave the drawing to OpenGL.
  CullStats run(const ParticleArrays &particles, const BrickSet &bricks, const Camera &camera,
                const SceneConfig &scene, DrawList *out, const RasterTarget *raster = nullptr);
  // The double-precision camera of the last run (the point path needs it after rendering).
  const ViewGeometry &geometry() const { return g_; }

 private:
  struct Candidate {
    glm::dvec3 c;  // view space
    double r;      // drawn radius
    uint32_t index;
    float scale;
  };
  // Scratch of one culling thread. hzb runs on two threads, each owning a strip of image columns
  // [x0, x1] and its own pyramid (see process_strips for why that is still exact).
  struct Workspace {
    Hzb hzb;
    CpuSphereRaster raster;
    int x0 = 0, x1 = -1;
    std::vector<Candidate> buffer, sorted;
    std::vector<uint32_t> bucket_counts;
    DrawList out;
    std::vector<int64_t> frustum_pp, cut_pp;  // per visible brick; -1: not gathered
  };
  template <typename Positions, typename Radii>
  void process(const Positions &pos, const Radii &radius, const Frustum &frustum,
               const CutPlanes &cuts, const SceneConfig &scene, const BrickSet &bricks,
               OcclusionMode mode, CullStats *stats, DrawList *out);
  // The image in column strips (two from kTwoStripsFrom px wide): the hzb pass, or (with
  // raster_) the fused CPU raster pass.
  template <typename Positions, typename Radii>
  void process_strips(const Positions &pos, const Radii &radius, const Frustum &frustum,
                      const CutPlanes &cuts, const SceneConfig &scene, const BrickSet &bricks,
                      CullStats *stats, DrawList *out);
  template <typename Positions, typename Radii>
  void run_strip(const Positions &pos, const Radii &radius, const Frustum &frustum,
                 const CutPlanes &cuts, const SceneConfig &scene, const BrickSet &bricks,
                 Workspace *w);

  template <typename Positions, typename Radii>
  void process_sorted(const Positions &pos, const Radii &radius, const Frustum &frustum,
                      const CutPlanes &cuts, const SceneConfig &scene, const BrickSet &bricks,
                      CullStats *stats, DrawList *out);
  // The kept prefix of one brick after cuts, per-particle frustum and the point path: straight
  // into `out`, or into w->buffer when occlusion still has to judge them.
  template <typename Positions, typename Radii>
  void gather(const Positions &pos, const Radii &radius, const Frustum &frustum,
              const CutPlanes &cuts, const SceneConfig &scene, const BrickSet &bricks,
              const VisibleBrick &v, bool keep_candidates, Workspace *w, CullStats *stats,
              DrawList *out) const;
  static void order_front_to_back(Workspace *w);  // w->buffer -> w->sorted
  bool occluded(OcclusionMode mode, const Candidate &c, Workspace *w);
  bool splat_sized(const glm::dvec3 &c, double r) const;
  void accept(const Candidate &c, bool point_path, DrawList *out) const;

  ViewGeometry g_;
  const RasterTarget *raster_ = nullptr;  // set while a fused raster pass runs
  bool occlusion_ = true;                 // strips test occlusion (false: raster without hzb)
  std::vector<VisibleBrick> visible_;
  std::vector<uint64_t> scratch_;
  Workspace ws_[2];
  NineSpheresGrid nine_;
};

std::string occlusion_mode_name(OcclusionMode mode);

}  // namespace lantern
