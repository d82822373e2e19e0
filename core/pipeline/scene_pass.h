// One scene on one scheduled step, on every rank: the camera, object-space ambient occlusion, the
// style's pass (sphere_scene_pass.h or density_scene_pass.h: drawing, compositing, finishing), and
// the image file and movie frame (scene_movie.h). Collective over the communicator.
#pragma once

#include "core/common/status.h"
#include "core/config/config.h"
#include "core/pipeline/scene_pass_inputs.h"
#include "core/pipeline/scene_stats.h"

namespace lantern {

// Renders `scene` and writes its image (and hands the frame to its movie). Every rank returns the
// same status.
Status run_scene_pass(const ScenePassInputs &in, const SceneConfig &scene, SceneBuffers *buffers,
                      SceneStats *stats);

}  // namespace lantern
