#include "core/pipeline/renderer_choice.h"

#include <algorithm>
#include <string>

#include "core/render/cpu_sphere_pass.h"

namespace lantern {
namespace {

// Spheres of at most this projected radius (pixels, at the camera's target) go to the CPU
// raster under `renderer: auto`. lantern-bench-render measured it 1.7-6x faster than llvmpipe
// for 10 k - 1 M spheres of 0.3 - 15.6 px; larger spheres stay on OpenGL, the reference renderer,
// until measured.
constexpr double kCpuRasterMaxPixels = 16.0;

// The configuration's choice, from the camera only. Measured in the final image's pixels, not
// the sample frame's, so `samples` never switches it.
bool wants_cpu_raster(RendererChoice asked, int image_height, const Camera &camera, double radius) {
  if (asked != RendererChoice::kAuto) return asked == RendererChoice::kCpu;
  const double distance = glm::length(camera.target - camera.eye);
  const double pixels_per_unit = 0.5 * image_height * camera.projection[1][1] /
                                 (camera.orthographic ? 1.0 : std::max(distance, 1e-300));
  return radius * pixels_per_unit <= kCpuRasterMaxPixels;
}

}  // namespace

bool draws_on_cpu(RendererChoice asked, int image_height, const Camera &camera, double max_radius,
                  bool have_opengl, bool see_through, BrickSelection *selection) {
  BrickSelection &sel = *selection;
  if (!have_opengl && !cpu_pass_serves(sel.mode)) {
    sel.stats.occlusion = "hzb (no OpenGL, instead of " + sel.stats.occlusion + ")";
    sel.mode = OcclusionMode::kHzb;
  }
  const bool cpu =
      !have_opengl || sel.mode == OcclusionMode::kProbabilistic ||
      (wants_cpu_raster(asked, image_height, camera, max_radius) && cpu_pass_serves(sel.mode));
  // See-through types hide nothing for sure: OpenGL's occlusion culling and the probabilistic
  // mode's confidence maps assume opaque occluders, so OpenGL culls none and probabilistic
  // becomes hzb (the CPU pass culls against the depth it drew: exact).
  if (see_through) {
    if (!cpu && sel.mode != OcclusionMode::kNone) {
      sel.stats.occlusion = "none (opacity < 1, instead of " + sel.stats.occlusion + ")";
      sel.mode = OcclusionMode::kNone;
    } else if (cpu && sel.mode == OcclusionMode::kProbabilistic) {
      sel.stats.occlusion = "hzb (opacity < 1, instead of probabilistic)";
      sel.mode = OcclusionMode::kHzb;
    }
  }
  return cpu;
}

}  // namespace lantern
