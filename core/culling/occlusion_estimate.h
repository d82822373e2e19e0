// What `occlusion: auto` decides on, per scene and frame, before any per-particle work: a cheap
// estimate of how much of the visible particles is hidden, in the spirit of the confidence
// maps of Ibrahim et al. 2022 but on bricks. Bricks are splatted front to back onto a coarse grid
// that keeps a transmittance per cell; a brick's spheres cover a share 1 - exp(-a) of its footprint
// (a = summed sphere area / footprint area, spheres placed at random), and the particles expected
// to show are those reached by the remaining transmittance. Thread-safety: pure function.
#pragma once

#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/culling/visible_brick.h"
#include "core/view/view_geometry.h"

namespace lantern {

// The coarse grid of transmittances behind that estimate. splat(v) returns how many of brick v's
// `keep` spheres are expected to show given the bricks splatted before it, then lets v's spheres
// absorb. Splat bricks front to back.
class CoarseTransmittance {
 public:
  explicit CoarseTransmittance(const ViewGeometry &g);
  double splat(const VisibleBrick &v, const ViewGeometry &g);

 private:
  std::vector<double> transmittance_;
  double cell_w_, cell_h_;
};

struct OcclusionChoice {
  OcclusionMode mode = OcclusionMode::kNone;
  double hidden_estimate = 0.0;  // estimated share of the candidates that is hidden
  double sphere_pixels = 0.0;    // typical projected sphere radius, pixels
  std::string reason;            // for the stats, e.g. "dense: est. 93% hidden"
};

// `visible` must be sorted front to back (near_depth ascending).
OcclusionChoice choose_occlusion(const VisibleBricks &visible, const ViewGeometry &g);

}  // namespace lantern
