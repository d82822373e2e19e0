// The overlays side of a scene (box, labels, legend, axes; core/finish/overlays/): the fonts they
// need checked when a configuration takes effect, and the overlays drawn on rank 0 over the
// finished image, before it goes to the image file and the movie.
#pragma once

#include <mpi.h>

#include <vector>

#include "core/camera/camera.h"
#include "core/common/status.h"
#include "core/config/config.h"
#include "core/pipeline/scene_pass_inputs.h"
#include "core/pipeline/scene_settings.h"
#include "core/pipeline/scene_stats.h"

namespace lantern {

// Local, the same on every rank: every scene's text has its font, and the build has text
// (kConfig naming the scene and what was looked for).
Status check_scene_overlays(const std::vector<SceneConfig> &scenes);

// Collective when the scene has overlays (else nothing happens): rank 0 draws them on
// buffers->frame (the finished image) through `camera` (the scene's frustum) with this frame's
// colour range; stats->overlays_ms. Same status on every rank (a font that vanished since the
// check fails naming it).
Status draw_scene_overlays(const ScenePassInputs &in, const SceneSettings &settings,
                           const Camera &camera, const SceneConfig &scene, SceneBuffers *buffers,
                           SceneStats *stats);

}  // namespace lantern
