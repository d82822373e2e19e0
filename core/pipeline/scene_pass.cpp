#include "core/pipeline/scene_pass.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <utility>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/color/colormap.h"
#include "core/common/collective_status.h"
#include "core/composite/band_compositing.h"
#include "core/composite/depth_compositor.h"
#include "core/composite/row_bands.h"
#include "core/composite/sample_downsampling.h"
#include "core/composite/screen_cues.h"
#include "core/config/file_pattern.h"
#include "core/culling/brick_selection.h"
#include "core/culling/cull_stage.h"
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
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

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

// The particle counts of the stats, summed over ranks in one reduction.
void sum_counts_over_ranks(MPI_Comm comm, const CullStats &local, SceneStats *stats) {
  int64_t in[6] = {local.drawn,      local.splatted,    local.frustum_culled,
                   local.cut_culled, local.lod_dropped, local.occlusion_culled};
  int64_t out[6] = {0, 0, 0, 0, 0, 0};
  MPI_Allreduce(in, out, 6, MPI_INT64_T, MPI_SUM, comm);
  stats->drawn = out[0];
  stats->splatted = out[1];
  stats->frustum_culled = out[2];
  stats->cut_culled = out[3];
  stats->lod_dropped = out[4];
  stats->occlusion_culled = out[5];
}

// Compositing into bands of the final image, for scenes with a stage after compositing
// (super-sampling's down-sampling, screen-space cues): the frames are composited so that every
// rank ends with its own row band of the merged frame (whole pixels, i.e. multiples of s sample
// rows), and every rank down-samples its band (s > 1) into *band, which then holds exactly the
// rank's row_band(height, ranks, rank) of the image. The merged frame is never gathered on one
// rank. Collective. The bands depend only on (height, ranks) and each output pixel only on its
// own samples, so the bytes never depend on the rank count. Fills *composite (time, method).
Status composite_into_image_band(MPI_Comm comm, Frame &frame, int s, BandFrame *band,
                                 CompositeStats *composite) {
  RowBand rows;
  if (Status st = composite_to_row_bands(comm, frame, s, &rows, composite); !st.ok()) return st;
  band->first = rows.y0 / s;
  band->owned = {rows.y0 / s, rows.y1 / s};
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  if (s > 1) {
    downsample_band(frame, s, band->first, band->owned.rows(), &band->frame);
  } else if (ranks == 1) {
    band->frame = std::move(frame);  // the band is the frame: no copy
  } else {
    const size_t begin = size_t(rows.y0) * size_t(frame.width), end = size_t(rows.y1) * frame.width;
    band->frame.width = frame.width;
    band->frame.height = rows.rows();
    band->frame.rgba.assign(frame.rgba.begin() + 4 * begin, frame.rgba.begin() + 4 * end);
    band->frame.depth.assign(frame.depth.begin() + begin, frame.depth.begin() + end);
  }
  return {};
}

// The image's bands to root's *image (on one rank the band is the image: moved, not copied).
Status assemble_image(MPI_Comm comm, BandFrame *band, int width, int height, Frame *image) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  if (ranks == 1) {
    *image = std::move(band->frame);
    return {};
  }
  return gather_row_bands(comm, 0, *band, width, height, image);
}

// Seed 004's counts over ranks: the slowest rank's iterations and samples, summed classes.
ProbabilisticStats reduce_probabilistic_stats(MPI_Comm comm, const ProbabilisticStats &local) {
  int64_t most[2] = {local.iterations, local.samples};
  int64_t sum[5] = {local.meshlets[0], local.meshlets[1], local.meshlets[2], local.meshlets[3],
                    local.particles_culled};
  MPI_Allreduce(MPI_IN_PLACE, most, 2, MPI_INT64_T, MPI_MAX, comm);
  MPI_Allreduce(MPI_IN_PLACE, sum, 5, MPI_INT64_T, MPI_SUM, comm);
  ProbabilisticStats all;
  all.iterations = most[0], all.samples = most[1];
  for (int k = 0; k < 4; ++k) all.meshlets[k] = sum[k];
  all.particles_culled = sum[4];
  return all;
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
    const BrickSet &bricks = in.scratch->bricks.for_step(*in.particles, in.step, brick_options(in),
                                                         &build_ms, &stats->bricks);
    stats->bricks_ms = build_ms;
    // A refit the runtime made ahead of the scan (BrickCache::refit_first) counts as culling too.
    const double ahead_ms = std::max(0.0, build_ms - ms_since(t0));
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
    cull =
        cpu ? in.scratch->cpu_pass.run(*in.particles, bricks, scene, selection, recipe, background,
                                       &frame, &draw, in.step, in.threads)
            : in.scratch->culler.cull(*in.particles, bricks, scene, selection, &draw, in.threads);
    stats->cull_ms = ms_since(t0) + ahead_ms;
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
    stats->per_rank = reduce_per_rank_stats(
        in.comm, 0, double(cull.drawn), double(cull.candidates - cull.drawn - cull.splatted),
        own_ms, in.local ? double(in.local->finite_count) : double(cull.candidates));

  CompositeStats cs;
  const bool cues = wants_screen_cues(scene);
  if (s_axis == 1 && !cues) {
    if (Status s = composite_frames(in.comm, frame, 0, CompositeMethod::kAuto, 0, &cs); !s.ok())
      return with_context(where + "compositing: ", std::move(s));
  } else {
    // A stage after compositing: every rank composites into, then works on, its own band of the
    // image; root gathers the finished bands. The merged frame is never gathered and handed out.
    t0 = Clock::now();
    BandFrame band;
    if (Status s = composite_into_image_band(in.comm, frame, s_axis, &band, &cs); !s.ok())
      return with_context(where + "compositing: ", std::move(s));
    stats->downsample_ms = ms_since(t0) - cs.milliseconds;
    if (cues) {
      // Screen-space cues on the final-resolution image, each rank its band plus the halo rows
      // its neighbours own. With super-sampling they need the image's camera (the sample
      // frame's has s times the pixels; the same frustum, so the same depths).
      t0 = Clock::now();
      Camera image_camera = camera;
      if (s_axis > 1)
        (void)make_camera(scene.camera, lo, hi, max_radius, scene.width, scene.height,
                          &image_camera, radius_source);  // succeeded above at s times the size
      Status cued =
          exchange_halo_rows(in.comm, scene.width, scene.height, screen_cue_halo(scene), &band);
      if (cued.ok()) cued = cue_band(in.comm, scene, image_camera, max_radius, &band);
      if (!cued.ok()) return with_context(where + "screen cues: ", std::move(cued));
      stats->cues_ms += ms_since(t0);
    }
    t0 = Clock::now();
    if (Status s = assemble_image(in.comm, &band, scene.width, scene.height, &buffers->frame);
        !s.ok())
      return with_context(where + "gathering the image: ", std::move(s));
    if (s_axis > 1) stats->downsample_ms += ms_since(t0);
  }
  stats->composite_ms = cs.milliseconds;
  stats->composite_method = cs.method;

  return write_scene_image(in, scene, camera, t_start, buffers, stats);
}

}  // namespace lantern
