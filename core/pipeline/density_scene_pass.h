// The rendering half of a density scene (`style: density`) on every rank: bricks and level of
// detail (core/render/density_pass.h), the fixed-point splat, the sum over ranks, and the
// transfer to colors on rank 0 (core/finish/density_transfer.h), leaving rank 0's frame ready
// for the scene's output. Collective over in.comm; every rank returns the same status.
#pragma once

#include <string>

#include "core/camera/camera.h"
#include "core/common/status.h"
#include "core/particles/radius_rule.h"
#include "core/pipeline/scene_pass_inputs.h"
#include "core/pipeline/scene_settings.h"
#include "core/pipeline/scene_stats.h"

namespace lantern {

// `settings`: the scene's, resolved once (scene_settings.h); `where`: "scenes 'name': ", in
// front of its error messages. `local`: this rank's verdict on the scene's inputs so far
// (missing arrays), agreed on here.
Status run_density_scene(const ScenePassInputs &in, const SceneSettings &settings,
                         const std::string &where, const Camera &camera, const RadiusRule &radius,
                         Status local, SceneBuffers *buffers, SceneStats *stats);

}  // namespace lantern
