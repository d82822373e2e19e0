// What culling needs of one scene: frustum, occlusion mode, level of detail, cutting planes.
// Resolved once per scene by the pipeline from the scene's configuration
// (core/pipeline/scene_settings.h), so culling never reads the rest of it.
//
// Plain value type. Units: the simulation's length unit (cutting planes).
#pragma once

#include <vector>

#include "core/config/config.h"
#include "core/culling/level_of_detail.h"

namespace lantern {

struct CullSettings {
  bool frustum = true;                             // culling.frustum
  OcclusionMode occlusion = OcclusionMode::kAuto;  // culling.occlusion, as configured
  NineSpheresRadius nine_spheres_radius = NineSpheresRadius::kWorld;
  ProbabilisticConfig probabilistic;  // occlusion: probabilistic's settings
  LodConfig lod;                      // budget, fraction, min_pixels, point_path
  // How a brick's kept spheres grow (density: volume; opaque spheres: coverage), and whether
  // lod.select: nearest applies (opaque spheres whose pass keeps a brick's front).
  LodGrowth lod_growth = LodGrowth::kCoverage;
  bool lod_nearest = false;
  std::vector<CutPlane> cuts;  // cut_planes (disabled ones cut nothing)
  // bonds: the scene draws the published bonds, as cylinders of this radius (bonds.radius).
  bool bonds = false;
  double bond_radius = 0.15;
};

}  // namespace lantern
