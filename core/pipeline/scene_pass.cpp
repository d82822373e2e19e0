#include "core/pipeline/scene_pass.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <utility>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/color/colormap.h"
#include "core/common/collective_status.h"
#include "core/common/ms_since.h"
#include "core/config/file_pattern.h"
#include "core/culling/brick_selection.h"
#include "core/culling/cull_stage.h"
#include "core/finish/finish_image.h"
#include "core/finish/screen_cues.h"
#include "core/output/image_writer.h"
#include "core/output/png/png_across_ranks.h"
#include "core/pipeline/density_scene_pass.h"
#include "core/render/cpu_sphere_pass.h"
#include "core/render/object_occlusion.h"
#include "core/render/point_splats.h"
#include "core/render/sphere_instances.h"

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;

// The arrays a scene needs that this rank did not publish.
Status check_scene_needs(const SceneConfig &scene, const RadiusRule &radius,
                         const ParticleArrays &p) {
  if (p.count() == 0) return {};
  if (radius.wanted && !radius.per_particle)
    return {StatusCode::kInvalidArgument, "scenes '" + scene.name +
                                              "': radius is per_particle but no radius array was "
                                              "published (lantern_particles.radius)"};
  if (scene.color.by == ColorBy::kScalar && !p.has_scalar())
    return {StatusCode::kInvalidArgument, "scenes '" + scene.name +
                                              "': color.by is scalar but no scalar array was "
                                              "published (lantern_particles.scalar)"};
  return {};
}

// Spheres of at most this projected radius (pixels, at the camera's target) go to the CPU
// raster under `renderer: auto`. lantern-bench-render measured it 1.7-6x faster than llvmpipe
// for 10 k - 1 M spheres of 0.3 - 15.6 px; larger spheres stay on OpenGL, the reference renderer,
// until measured.
constexpr double kCpuRasterMaxPixels = 16.0;

// The renderer a scene uses, decided from the configuration and the camera only, so every rank
// decides the same (the two renderers may differ in the last bit of a pixel). Measured in the
// final image's pixels (scene.height), not the sample frame's, so `samples` never switches it.
bool wants_cpu_raster(const SceneConfig &scene, const Camera &camera, double radius) {
  if (scene.renderer != RendererChoice::kAuto) return scene.renderer == RendererChoice::kCpu;
  const double distance = glm::length(camera.target - camera.eye);
  const double pixels_per_unit = 0.5 * scene.height * camera.projection[1][1] /
                                 (camera.orthographic ? 1.0 : std::max(distance, 1e-300));
  return radius * pixels_per_unit <= kCpuRasterMaxPixels;
}

// The composited image (rank 0's frame) to the scene's file. Collective; same status everywhere.
Status write_scene_image(const ScenePassInputs &in, const SceneConfig &scene, const Camera &camera,
                         Clock::time_point t_start, SceneBuffers *buffers, SceneStats *stats) {
  int rank = 0;
  MPI_Comm_rank(in.comm, &rank);
  const std::string where = "scenes '" + scene.name + "': ";
  Clock::time_point t0;
  Status written;
  if (scene.output.format == ImageFormat::kPng && !scene.output.asynchronous) {
    // Every rank compresses a share of the PNG: the root's encoder is off the critical path.
    t0 = Clock::now();
    stats->file = expand_pattern(scene.output.pattern, in.step, scene.name);
    written = with_context(
        where, write_png_across_ranks(in.comm, 0, buffers->frame, scene.width, scene.height,
                                      scene.output.compression_level, stats->file));
    stats->write_ms = ms_since(t0);
    stats->total_ms = ms_since(t_start);
    return agree_on_status(in.comm, written);
  }
  if (rank == 0) {
    t0 = Clock::now();
    stats->file = expand_pattern(scene.output.pattern, in.step, scene.name);
    const auto to_distance = [camera](float d) {  // a copy: it may outlive this call
      return float(camera.window_depth_to_distance(d));
    };
    written = with_context(
        where, scene.output.asynchronous
                   ? buffers->writer.submit(std::move(buffers->frame), scene.output, stats->file,
                                            to_distance)
                   : write_image(buffers->frame, scene.output, stats->file, to_distance));
    stats->write_ms = ms_since(t0);
  }
  stats->total_ms = ms_since(t_start);
  return broadcast_status(in.comm, written, 0);
}

}  // namespace

Status run_scene_pass(const ScenePassInputs &in, const SceneConfig &scene, SceneBuffers *buffers,
                      SceneStats *stats) {
  const auto t_start = Clock::now();
  stats->name = scene.name;

  // Every rank has the same inputs here, so these outcomes agree without communication.
  auto t0 = Clock::now();
  Camera camera;
  const RadiusRule radius = RadiusRule::of(scene, *in.particles);  // for every stage below
  const double max_radius = radius.max_radius(in.global);
  const glm::dvec3 lo{in.global.lo[0], in.global.lo[1], in.global.lo[2]};
  const glm::dvec3 hi{in.global.hi[0], in.global.hi[1], in.global.hi[2]};
  const std::string where = "scenes '" + scene.name + "': ";
  const RadiusSource radius_source =
      radius.wanted ? RadiusSource::kParticles : RadiusSource::kConfig;
  // Super-sampling renders the same frustum at s times the width and height (an s x s grid of
  // samples per pixel, sample_downsampling.h); every stage up to compositing sees sample pixels.
  const int s_axis = scene.samples_per_axis();
  Frame &frame = s_axis > 1 ? buffers->samples : buffers->frame;
  if (s_axis == 1 && !buffers->samples.rgba.empty())
    buffers->samples = Frame();  // a live change back to 1 sample frees the sample frame
  stats->samples = scene.samples;
  stats->sample_width = scene.width * s_axis;
  stats->sample_height = scene.height * s_axis;
  if (Status s = make_camera(scene.camera, lo, hi, max_radius, scene.width * s_axis,
                             scene.height * s_axis, &camera, radius_source);
      !s.ok())
    return with_context(where, std::move(s));
  stats->camera_ms = ms_since(t0);

  // Object-space ambient occlusion: a density volume reduced over every rank (collective, so
  // before anything a rank may skip); colours are scaled as particles are drawn.
  const bool object_ao = scene.ambient_occlusion.enabled &&
                         scene.ambient_occlusion.method == AmbientOcclusionMethod::kObject;
  OcclusionVolume occlusion;
  if (object_ao) {
    t0 = Clock::now();
    const double cell =
        scene.ambient_occlusion.radius.value_or(kDefaultAoRadiusInSphereRadii * max_radius);
    if (Status s = occlusion.build(in.comm, *in.particles, in.global, scene.cuts, cell,
                                   scene.ambient_occlusion.strength);
        !s.ok())
      return with_context(where, std::move(s));
    stats->cues_ms = ms_since(t0);
  }

  Status local = check_scene_needs(scene, radius, *in.particles);
  if (scene.style == SceneStyle::kDensity) {
    if (Status s = run_density_scene(in, scene, camera, radius, std::move(local), buffers, stats);
        !s.ok())
      return s;
    return write_scene_image(in, scene, camera, t_start, buffers, stats);
  }
  CullStats cull;
  if (local.ok()) {
    // Bricks, culling and level of detail: what to draw.
    t0 = Clock::now();
    double build_ms = 0.0;
    const BrickSet &bricks =
        in.scratch->bricks.for_step(*in.particles, in.step, &build_ms, &stats->bricks);
    stats->bricks_ms = build_ms;
    DrawList &draw = in.scratch->draw;
    BrickSelection &selection = in.scratch->selection;
    select_bricks(bricks, camera, scene, radius, &selection, &buffers->cut_counts);
    InstanceRecipe recipe = make_recipe(*in.particles, scene, radius, camera, in.global);
    if (object_ao) recipe.occlusion = &occlusion;
    const Rgb8 bg = to_rgb8(scene.background);
    const uint8_t background[4] = {bg[0], bg[1], bg[2], 255};
    // The renderer, decided here once: from the configuration, the camera and the occlusion mode
    // the selection resolved, so every rank decides the same. Without OpenGL (in.renderer null
    // on every rank alike) the CPU raster draws, culling exactly (hzb) where nine-spheres was
    // asked for, which only it could not serve.
    if (!in.renderer && !cpu_pass_serves(selection.mode)) {
      selection.stats.occlusion = "hzb (no OpenGL, instead of " + selection.stats.occlusion + ")";
      selection.mode = OcclusionMode::kHzb;
    }
    const bool cpu =
        !in.renderer || selection.mode == OcclusionMode::kProbabilistic ||
        (wants_cpu_raster(scene, camera, max_radius) && cpu_pass_serves(selection.mode));
    // See-through types (opacity) hide nothing for sure: OpenGL's occlusion culling and the
    // probabilistic mode's confidence maps assume opaque occluders, so OpenGL culls none and
    // probabilistic becomes hzb (the CPU pass culls against the depth it drew: exact).
    if (!recipe.alpha_by_type.empty()) {
      if (!cpu && selection.mode != OcclusionMode::kNone) {
        selection.stats.occlusion =
            "none (opacity < 1, instead of " + selection.stats.occlusion + ")";
        selection.mode = OcclusionMode::kNone;
      } else if (cpu && selection.mode == OcclusionMode::kProbabilistic) {
        selection.stats.occlusion = "hzb (opacity < 1, instead of probabilistic)";
        selection.mode = OcclusionMode::kHzb;
      }
    }
    stats->renderer = cpu ? "cpu" : "opengl";
    cull = cpu ? in.scratch->cpu_pass.run(*in.particles, bricks, scene, selection, recipe,
                                          background, &frame, &draw, in.step)
               : in.scratch->culler.cull(*in.particles, bricks, scene, selection, &draw);
    stats->cull_ms = ms_since(t0);
    stats->occlusion = cull.occlusion;

    if (!cpu) {
      t0 = Clock::now();
      if (draw.everything)
        build_all_instances(recipe, &buffers->instances);
      else
        build_selected_instances(recipe, draw.spheres, &buffers->instances);
      std::vector<uint64_t>().swap(draw.spheres);  // only the instances outlive this point
      stats->instances_ms = ms_since(t0);
      RenderTimings timings;
      RenderView view = camera.render_view(background);
      view.lighting = scene.lighting;
      local = with_context(where, in.renderer->render(view, buffers->instances.data(),
                                                      buffers->instances.size(), &frame, &timings));
      stats->draw_ms = timings.draw_ms;
      stats->readback_ms = timings.readback_ms;
    }
    if (!draw.points.empty()) {
      t0 = Clock::now();
      splat_points(
          *in.particles, recipe.per_particle_radius, recipe.radius, draw.points, selection.g,
          [&recipe](int64_t i) { return recipe.color(i); }, &frame,
          recipe.alpha_by_type.empty() ? AlphaOf()
                                       : AlphaOf([&recipe](int64_t i) { return recipe.alpha(i); }),
          scene.lighting);
      std::vector<uint64_t>().swap(draw.points);
      stats->draw_ms += ms_since(t0);
    }
  }
  const double own_ms = ms_since(t_start);  // this rank's work, before waiting on the others
  if (Status s = agree_on_status(in.comm, local); !s.ok()) return s;
  sum_counts_over_ranks(in.comm, cull, stats);
  if (scene.culling.occlusion == OcclusionMode::kProbabilistic)  // the same on every rank
    stats->probabilistic = reduce_probabilistic_stats(in.comm, cull.probabilistic);
  stats->culled = in.global.finite_count - stats->drawn - stats->splatted;
  if (in.per_rank_stats)
    stats->per_rank =
        reduce_per_rank_stats(in.comm, 0, double(cull.drawn),
                              double(cull.candidates - cull.drawn - cull.splatted), own_ms);

  // The composited image finished (down-sampling, screen-space cues) on root. The cues need the
  // image's camera: with super-sampling the sample frame's has s times the pixels (the same
  // frustum, so the same depths).
  Camera image_camera = camera;
  if (s_axis > 1 && wants_screen_cues(scene))
    (void)make_camera(scene.camera, lo, hi, max_radius, scene.width, scene.height, &image_camera,
                      radius_source);  // succeeded above at s times the size
  FinishStats finished;
  if (Status s =
          finish_image(in.comm, frame, scene, image_camera, max_radius, &buffers->frame, &finished);
      !s.ok())
    return with_context(where, std::move(s));
  stats->downsample_ms = finished.downsample_ms;
  stats->cues_ms += finished.cues_ms;
  stats->composite_ms = finished.composite.milliseconds;
  stats->composite_method = finished.composite.method;

  return write_scene_image(in, scene, camera, t_start, buffers, stats);
}

}  // namespace lantern
