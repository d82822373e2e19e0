// The rendering half of a sphere scene (`style: spheres`) on every rank: the step's bricks, the
// scene drawn on this rank (rank_draw.h), the counts summed over ranks, and the frames
// composited and finished into rank 0's image (core/finish/finish_image.h), leaving rank 0's
// frame ready for the scene's output. Collective over in.comm; every rank returns the same status.
#pragma once

#include <chrono>
#include <string>

#include "core/camera/camera.h"
#include "core/common/status.h"
#include "core/particles/radius_rule.h"
#include "core/pipeline/scene_pass_inputs.h"
#include "core/pipeline/scene_settings.h"
#include "core/pipeline/scene_stats.h"
#include "core/render/object_occlusion.h"

namespace lantern {

// `settings`: the scene's, resolved once (scene_settings.h); `where`: "scenes 'name': ", in
// front of its error messages. `camera`: at the frame's size (s = samples per axis times the
// image's); `image_camera`: the final image's, for the screen cues. `occlusion`: object-space
// ambient occlusion, or null. `local`: this rank's verdict on the scene's inputs so far (missing
// arrays), agreed on here. `t_start`: when the scene began on this rank (its own time, for the
// per-rank statistics).
Status run_sphere_scene(const ScenePassInputs &in, const SceneSettings &settings,
                        const std::string &where, const Camera &camera, const Camera &image_camera,
                        const RadiusRule &radius, const OcclusionVolume *occlusion, Status local,
                        std::chrono::steady_clock::time_point t_start, SceneBuffers *buffers,
                        SceneStats *stats);

}  // namespace lantern
