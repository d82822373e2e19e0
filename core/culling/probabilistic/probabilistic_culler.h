// Ibrahim et al.'s probabilistic occlusion culling on the CPU (occlusion: probabilistic): which
// meshlets of the visible bricks are occluded with confidence C_occ, found by sampling a few
// occluder meshlets per node and pass into double-buffered depth-confidence maps.
//
// Per frame: every meshlet of a visible brick (node) starts potentially visible (P). Each
// iteration runs kPassesPerIteration passes; a pass picks `budget` meshlets per node from P
// (then from L), shuffled by a keyed random permutation so no candidate starves (§5.2), and
// ray-casts their particles at one jittered sub-pixel position per pixel; each pixel's nearest
// hit is one sample for algorithm 1 (depth_confidence.h), whose acceptance probability comes from
// D(t) cast through the density volume (density_volume.h). After the passes the cull buffer's
// confidence pyramid (eq. 23) tests each node, then each of its meshlets not yet occluded: a box
// that passes the depth test is P; one that fails is O above C_occ, M above C_occ / 2, L below
// (§5.1); classes only move up. Meshlets reaching O leave the density volume. Iterations stop
// when no class changed for `patience` iterations (§5.3; "no" meaning at most quiet_share, 1%,
// of the meshlets not yet occluded, so exactly none below 100 of them; lantern-bench's +strict
// modes take 0, the paper's letter), at most kMaxIterations.
//
// Approximate: a meshlet in O may hold visible particles (with probability about 1 - C_occ per
// decision); a meshlet that passed the depth test is never culled. Every random number is a hash
// of (step, pixel or node, sample, iteration), so a rerun on the same ranks gives the same classes.
// Decisions use this rank's particles only, so the culled set (and the image) depends on how the
// particles are split over ranks.
//
// Ownership: owns its meshlets (rebuilt when the bricks' generation changes), buffers and classes.
// Thread-safety: one culler per thread; run() uses the calling thread only.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/config/config.h"
#include "core/culling/brick_selection.h"
#include "core/culling/cull_stats.h"
#include "core/culling/probabilistic/density_volume.h"
#include "core/culling/probabilistic/depth_confidence.h"
#include "core/culling/probabilistic/meshlets.h"
#include "core/particles/particle_arrays.h"

namespace lantern {

// Ibrahim et al.'s occlusion classes (§5.1), ordered by confidence of occlusion.
enum class OcclusionClass : uint8_t { kPotentiallyVisible = 0, kLow, kMedium, kOccluded };

inline constexpr int kPassesPerIteration = 4;
inline constexpr int kMaxIterations = 64;

class ProbabilisticCuller {
 public:
  // Classifies the meshlets of `sel`'s visible bricks (sel.mode must be probabilistic) for the
  // frame of step `step`.
  // `settings`: the scene's culling.probabilistic keys.
  ProbabilisticStats run(const ParticleArrays &particles, const BrickSet &bricks,
                         const ProbabilisticConfig &settings, const BrickSelection &sel,
                         int64_t step);

  const MeshletSet &meshlets() const { return meshlets_; }
  // The class of meshlet m after the last run (meaningful for meshlets of visible bricks).
  OcclusionClass class_of(uint32_t m) const { return OcclusionClass(classes_[m]); }
  // The cull buffer after the last run, row by row from the top (tests).
  const std::vector<ConfidencePixel> &pixels() const { return pixels_; }

 private:
  // This pass's ray per pixel through its jittered sub-pixel position (keys kx, ky), worked out
  // once per pass rather than once per sphere covering the pixel.
  void jitter_rays(const ViewGeometry &g, uint64_t kx, uint64_t ky);
  // Casts one occluder sphere (view-space centre c, radius r) along this pass's rays into the
  // pass buffers (nearest hit per pixel).
  void sample_sphere(const ViewGeometry &g, const glm::dvec3 &c, double r);

  MeshletSet meshlets_;
  std::vector<uint8_t> classes_;
  std::vector<ConfidencePixel> pixels_;
  std::vector<float> pass_depth_, pass_alpha_;
  // Per pixel, this pass's ray: perspective (x, y, -1) and its squared length; orthographic the
  // view-space (x, y) it starts from.
  std::vector<double> ray_x_, ray_y_, ray_l2_;
  std::vector<PixelRect> rects_;  // per meshlet of a visible brick
  std::vector<double> nears_;
  std::vector<uint32_t> open_p_, open_l_;  // per visible brick: its meshlets in P and in L
  struct ViewSphere {
    glm::dvec3 c;  // view-space centre
    double r;      // radius, level-of-detail growth included
  };
  // The kept particles of the visible bricks in meshlet order, during run() only; meshlet m's
  // are [sphere_span_[m].first, sphere_span_[m].second).
  std::vector<ViewSphere> spheres_;
  std::vector<std::pair<uint32_t, uint32_t>> sphere_span_;
  DensityVolume volume_;
  ConfidencePyramid pyramid_;
};

}  // namespace lantern
