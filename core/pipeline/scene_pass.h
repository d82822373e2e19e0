// One scene on one scheduled step, on every rank: camera, the spheres to draw, rendering,
// compositing across ranks, and the image file on rank 0. Collective over the communicator.
#pragma once

#include "core/common/status.h"
#include "core/config/config.h"
#include "core/pipeline/scene_pass_inputs.h"
#include "core/pipeline/scene_stats.h"

namespace lantern {

// Renders `scene` and writes its image. Every rank returns the same status.
Status run_scene_pass(const ScenePassInputs &in, const SceneConfig &scene, SceneBuffers *buffers,
                      SceneStats *stats);

}  // namespace lantern
