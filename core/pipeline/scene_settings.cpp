#include "core/pipeline/scene_settings.h"

#include "core/camera/camera_path.h"

namespace lantern {

CameraConfig camera_settings(const SceneConfig &scene, int64_t step) {
  return camera_at_step(scene.camera, step);
}

RadiusRule radius_rule(const SceneConfig &scene, const ParticleArrays &particles) {
  return RadiusRule::of(scene.per_particle_radius, scene.radius, particles);
}

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
  c.bonds = scene.bonds.enabled && scene.style == SceneStyle::kSpheres;
  c.bond_radius = scene.bonds.radius;
  return c;
}

ShadingSettings shading_settings(const SceneConfig &scene) {
  ShadingSettings s;
  s.color = scene.color;
  s.opacity = scene.opacity;
  s.lighting = scene.lighting;
  s.background = scene.background;
  s.transparent_background = scene.transparent_background;
  s.bonds = scene.bonds;
  return s;
}

OverlaySettings overlay_settings(const SceneConfig &scene) {
  OverlaySettings o;
  o.scene_name = scene.name;
  o.labels = scene.labels;
  o.legend = scene.legend;
  o.legend_colors.by = scene.color.by;
  o.legend_colors.colormap = scene.color.colormap;
  o.legend_colors.colormap_colors = scene.color.colormap_colors;
  o.legend_colors.reverse = scene.color.reverse;
  o.legend_colors.palette = scene.color.palette;
  o.box = scene.box;
  o.axes = scene.axes;
  o.font = scene.font;
  return o;
}

FinishSettings finish_settings(const SceneConfig &scene) {
  FinishSettings f;
  f.width = scene.width;
  f.height = scene.height;
  f.samples_per_axis = scene.samples_per_axis();
  // Ambient occlusion is a screen cue only with the screen method (object-space occlusion
  // darkens the particles as they are drawn).
  f.cues.ambient_occlusion = scene.ambient_occlusion;
  f.cues.ambient_occlusion.enabled =
      scene.ambient_occlusion.enabled &&
      scene.ambient_occlusion.method == AmbientOcclusionMethod::kScreen;
  f.cues.outline = scene.outline;
  f.cues.depth_cue = scene.depth_cue;
  f.cues.background = scene.background;
  f.cues.transparent_background = scene.transparent_background;
  f.transparent_background = scene.transparent_background;
  f.density = scene.density;
  f.overlays = overlay_settings(scene);
  return f;
}

SceneSettings scene_settings(const SceneConfig &scene) {
  SceneSettings s;
  s.cull = cull_settings(scene);
  s.shading = shading_settings(scene);
  s.finish = finish_settings(scene);
  s.renderer = scene.renderer;
  return s;
}

}  // namespace lantern
