#include "core/pipeline/scene_stats.h"

namespace lantern {

nlohmann::json SceneStats::to_json() const {
  return {{"scene", name},
          {"file", file},
          {"ms",
           {{"camera", camera_ms},
            {"cull", cull_ms},
            {"bricks", bricks_ms},
            {"instances", instances_ms},
            {"draw", draw_ms},
            {"readback", readback_ms},
            {"composite", composite_ms},
            {"write", write_ms},
            {"total", total_ms}}},
          {"particles",
           {{"drawn", drawn},
            {"splatted", splatted},
            {"culled", culled},
            {"frustum_culled", frustum_culled},
            {"cut_culled", cut_culled},
            {"lod_dropped", lod_dropped},
            {"occlusion_culled", occlusion_culled}}},
          {"composite_method", composite_method},
          {"occlusion", occlusion},
          {"renderer", renderer},
          {"bricks", bricks}};
}

}  // namespace lantern
