#include "core/pipeline/scene_pass.h"

#include <chrono>

#include "core/camera/camera.h"
#include "core/color/colormap.h"
#include "core/composite/depth_compositor.h"
#include "core/output/file_pattern.h"
#include "core/output/image_writer.h"
#include "core/pipeline/collective_status.h"
#include "core/pipeline/sphere_instances.h"

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The arrays a scene needs that this rank did not publish.
Status check_scene_needs(const SceneConfig &scene, const ParticleArrays &p) {
  if (p.count() == 0) return {};
  if (scene.per_particle_radius && !p.has_radius())
    return {LANTERN_ERR_INVALID_ARGUMENT, "scenes '" + scene.name +
                                              "': radius is per_particle but no radius array was "
                                              "published (lantern_particles.radius)"};
  if (scene.color.by == ColorBy::kScalar && !p.has_scalar())
    return {LANTERN_ERR_INVALID_ARGUMENT, "scenes '" + scene.name +
                                              "': color.by is scalar but no scalar array was "
                                              "published (lantern_particles.scalar)"};
  return {};
}

int64_t sum_over_ranks(MPI_Comm comm, int64_t local) {
  int64_t total = 0;
  MPI_Allreduce(&local, &total, 1, MPI_INT64_T, MPI_SUM, comm);
  return total;
}

}  // namespace

Status run_scene_pass(const ScenePassInputs &in, const SceneConfig &scene, SceneBuffers *buffers,
                      SceneStats *stats) {
  const auto t_start = Clock::now();
  int rank = 0;
  MPI_Comm_rank(in.comm, &rank);
  stats->name = scene.name;

  // Every rank has the same inputs here, so these outcomes agree without communication.
  auto t0 = Clock::now();
  Camera camera;
  const double max_radius =
      scene.per_particle_radius ? std::max(in.global.max_radius, 0.0) : scene.radius;
  const glm::dvec3 lo{in.global.lo[0], in.global.lo[1], in.global.lo[2]};
  const glm::dvec3 hi{in.global.hi[0], in.global.hi[1], in.global.hi[2]};
  if (auto e = make_camera(scene.camera, lo, hi, max_radius, scene.width, scene.height, &camera);
      !e.empty())
    return {LANTERN_ERR_CONFIG, "scenes '" + scene.name + "': " + e};
  stats->camera_ms = ms_since(t0);

  Status local = check_scene_needs(scene, *in.particles);
  if (local.ok()) {
    t0 = Clock::now();
    const InstanceRecipe recipe = make_recipe(*in.particles, scene, camera, in.global);
    build_all_instances(recipe, &buffers->instances);
    stats->instances_ms = ms_since(t0);
    stats->occlusion = "none";
    const Rgb8 bg = to_rgb8(scene.background);
    const uint8_t background[4] = {bg[0], bg[1], bg[2], 255};
    RenderTimings timings;
    const std::string e =
        in.renderer->render(camera.render_view(background), buffers->instances.data(),
                            buffers->instances.size(), &buffers->frame, &timings);
    if (!e.empty()) local = {LANTERN_ERR_GL, "scenes '" + scene.name + "': " + e};
    stats->draw_ms = timings.draw_ms;
    stats->readback_ms = timings.readback_ms;
  }
  if (Status s = agree_on_status(in.comm, local); !s.ok()) return s;
  stats->drawn = sum_over_ranks(in.comm, int64_t(buffers->instances.size()));
  stats->culled = in.global.finite_count - stats->drawn;

  const CompositeStats cs = composite_frames(in.comm, buffers->frame, 0, CompositeMethod::kAuto);
  if (!cs.ok()) return {LANTERN_ERR_MPI, "scenes '" + scene.name + "': compositing: " + cs.error};
  stats->composite_ms = cs.milliseconds;
  stats->composite_method = cs.method;

  Status written;
  if (rank == 0) {
    t0 = Clock::now();
    stats->file = expand_pattern(scene.output.pattern, in.step, scene.name);
    const auto to_distance = [&camera](float d) {
      return float(camera.window_depth_to_distance(d));
    };
    if (auto e = write_image(buffers->frame, scene.output, stats->file, to_distance); !e.empty())
      written = {LANTERN_ERR_IO, "scenes '" + scene.name + "': " + e};
    stats->write_ms = ms_since(t0);
  }
  stats->total_ms = ms_since(t_start);
  return broadcast_status(in.comm, written, 0);
}

}  // namespace lantern
