// The small values each stage takes, resolved once per scene from the scene's configuration:
// the stages below the pipeline never read a SceneConfig, only what they need of it.
//
// Plain value types; run_scene_pass resolves a SceneSettings once per scene and step and hands
// each stage its part.
#pragma once

#include "core/config/config.h"
#include "core/culling/cull_settings.h"
#include "core/finish/finish_image.h"
#include "core/particles/particle_arrays.h"
#include "core/particles/radius_rule.h"
#include "core/render/shading_settings.h"

namespace lantern {

// Every stage's values for one scene.
struct SceneSettings {
  CullSettings cull;        // culling
  ShadingSettings shading;  // rendering
  FinishSettings finish;    // finishing (cues, down-sampling, density transfer)
  RendererChoice renderer = RendererChoice::kAuto;  // renderer: the pipeline's choice of renderer
  // > 0: the finished image is left in row bands of multiples of this many rows, one per rank, and
  // written from them (scene_pass.cpp decides it per frame from the output and the rank count);
  // 0: gathered on rank 0.
  int image_band_rows = 0;
};

SceneSettings scene_settings(const SceneConfig &scene);

// The camera of the scene at `step`: a moving camera (camera.path, camera.orbit) resolved to the
// static camera it is at that step (core/camera/camera_path.h), from the configuration and the
// step alone, so the same on every rank. Resolved once per scene and frame.
CameraConfig camera_settings(const SceneConfig &scene, int64_t step);

// How the scene sizes this rank's particles (`radius:`), for every stage that needs it.
RadiusRule radius_rule(const SceneConfig &scene, const ParticleArrays &particles);

// Culling's: frustum, occlusion, level of detail (and how it grows spheres for the style),
// cutting planes.
CullSettings cull_settings(const SceneConfig &scene);

// Rendering's: colors, opacity, light, background.
ShadingSettings shading_settings(const SceneConfig &scene);

// The overlays': labels, legend (with the scene's colours), box, axes, font.
OverlaySettings overlay_settings(const SceneConfig &scene);

// Finishing's: the image's size, the samples per axis, the screen-space cues.
FinishSettings finish_settings(const SceneConfig &scene);

}  // namespace lantern
