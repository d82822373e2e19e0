#include "core/pipeline/scene_settings.h"

namespace lantern {

CullSettings cull_settings(const SceneConfig &scene) {
  CullSettings c;
  c.frustum = scene.culling.frustum;
  c.occlusion = scene.culling.occlusion;
  c.nine_spheres_radius = scene.culling.nine_spheres_radius;
  c.probabilistic = scene.culling.probabilistic;
  c.lod = scene.lod;
  // Density's weights carry the brightness, so its footprints keep the brick's volume; opaque
  // spheres keep the pixels a brick covers.
  c.lod_growth = scene.style == SceneStyle::kDensity ? LodGrowth::kVolume : LodGrowth::kCoverage;
  // lod.select: nearest is for opaque spheres; the probabilistic culler draws meshlet slots of
  // the uniform prefix, so it keeps that.
  c.lod_nearest = scene.lod.select == LodSelect::kNearest && scene.style == SceneStyle::kSpheres &&
                  scene.culling.occlusion != OcclusionMode::kProbabilistic;
  c.cuts = scene.cuts;
  return c;
}

ShadingSettings shading_settings(const SceneConfig &scene) {
  ShadingSettings s;
  s.color = scene.color;
  s.opacity = scene.opacity;
  s.lighting = scene.lighting;
  s.background = scene.background;
  return s;
}

}  // namespace lantern
