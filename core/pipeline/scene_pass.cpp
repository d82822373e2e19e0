#include "core/pipeline/scene_pass.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/camera/camera.h"
#include "core/common/collective_status.h"
#include "core/common/guarded_status.h"
#include "core/common/ms_since.h"
#include "core/config/file_pattern.h"
#include "core/finish/screen_cues.h"
#include "core/output/image_writer.h"
#include "core/output/png/png_across_ranks.h"
#include "core/pipeline/density_scene_pass.h"
#include "core/pipeline/scene_movie.h"
#include "core/pipeline/scene_overlays.h"
#include "core/pipeline/scene_settings.h"
#include "core/pipeline/sphere_scene_pass.h"
#include "core/render/object_occlusion.h"

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;

// The arrays a scene needs that this rank did not publish.
Status check_scene_needs(const SceneConfig &scene, const RadiusRule &radius,
                         const ParticleArrays &p, const BondArrays *bonds) {
  if (scene.bonds.enabled && scene.bonds.color == BondColorBy::kType && bonds &&
      bonds->count() > 0 && !bonds->has_type())
    return {StatusCode::kInvalidArgument, "scenes '" + scene.name +
                                              "': bonds.color is by_type but no bond type array "
                                              "was published (lantern_bonds.type)"};
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

// Where single-precision stages lose the picture (measured by rendering one scene at power-of-two
// scales, which are exact, against its unit-scale image): the eye's distance to the farthest
// point of the scene above 1e18 (OpenGL, exact at 1.6e19, was blank at 3.3e19; spheres zoomed in
// on broke near 1e20, an orthographic view once a radius passed 1.8e19: squares of view-space
// lengths overflow float), and screen ambient occlusion where the scene spans less than 1e-8 or
// more than 1e10 (exact from about 2e-8 to 1e11: its normals are cross products of neighbouring
// pixels' offsets, fourth powers of lengths in float). Empty where neither.
std::string single_precision_problem(const SceneConfig &scene, const Camera &camera,
                                     const glm::dvec3 &lo, const glm::dvec3 &hi,
                                     double max_radius) {
  double reach = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 p{corner & 1 ? hi.x : lo.x, corner & 2 ? hi.y : lo.y,
                       corner & 4 ? hi.z : lo.z};
    reach = std::max(reach, glm::length(p - camera.eye) + max_radius);
  }
  const double span = glm::length(hi - lo) + 2.0 * max_radius;
  char text[320];
  if (reach > 1e18) {
    std::snprintf(text, sizeof text,
                  "the scene's farthest point is %g from the eye, beyond 1e18: stages in "
                  "single precision (OpenGL, orthographic views, close-up spheres, screen cues) "
                  "may draw nothing or lose detail; express positions in larger units",
                  reach);
    return text;
  }
  const bool screen_ao = scene.ambient_occlusion.enabled &&
                         scene.ambient_occlusion.method == AmbientOcclusionMethod::kScreen;
  if (screen_ao && (span < 1e-8 || span > 1e10)) {
    std::snprintf(text, sizeof text,
                  "the scene spans %g, outside [1e-8, 1e10]: screen ambient occlusion's normals "
                  "lose precision in single precision; express positions in other units",
                  span);
    return text;
  }
  return {};
}

// The frame's own scalar range (reduced over ranks), if any particle had a finite scalar.
std::optional<std::array<double, 2>> scalar_range_of(const Extent &global) {
  if (!global.has_scalar_range()) return std::nullopt;
  return std::array<double, 2>{global.scalar_min, global.scalar_max};
}

// Row bands the finished image can stay in (SceneSettings::image_band_rows), or 0: when its only
// use is a PNG file written now (no movie, no overlays drawn on root, no background writer) and
// the file's bands divide the image. Then the merged frame is never gathered on rank 0 to be
// handed out again for compression: every rank composites, cues (with the halo rows of its
// neighbours' bands) and compresses its own bands (write_png_from_row_bands). With more ranks than
// bands (8 from 256 rows) the first ranks hold one band each and the others none: still 1/8 of the
// image at most on any rank, where rank 0 would receive all of it. The same decision on every rank.
int image_band_rows(MPI_Comm comm, const SceneConfig &scene, const SceneSettings &settings) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  const OutputConfig &out = scene.output;
  if (ranks == 1 || out.format != ImageFormat::kPng || out.asynchronous || !out.images ||
      out.movie.enabled || settings.finish.overlays.any())
    return 0;
  return png_band_rows(scene.height, scene.width);
}

// The composited image (rank 0's frame) to the scene's file. Collective; same status everywhere.
Status write_image_file(const ScenePassInputs &in, const SceneConfig &scene, const Camera &camera,
                        Clock::time_point t_start, SceneBuffers *buffers, SceneStats *stats) {
  int rank = 0;
  MPI_Comm_rank(in.comm, &rank);
  const std::string where = "scenes '" + scene.name + "': ";
  Clock::time_point t0;
  Status written;
  if (buffers->image_band) {
    // The image is in row bands, one per rank: each compresses its own bands where they are.
    t0 = Clock::now();
    stats->file = expand_pattern(scene.output.pattern, in.step, scene.name);
    const ImageBand &band = *buffers->image_band;
    const uint8_t *rows =
        band.held->rgba.data() + size_t(band.rows.y0 - band.first) * size_t(scene.width) * 4;
    written = with_context(
        where, write_png_from_row_bands(in.comm, 0, rows, band.rows.y0, band.rows.y1, scene.width,
                                        scene.height, scene.output.compression_level, stats->file,
                                        in.threads));
    stats->write_ms = ms_since(t0);
    stats->total_ms = ms_since(t_start);
    return agree_on_status(in.comm, written);
  }
  if (scene.output.format == ImageFormat::kPng && !scene.output.asynchronous) {
    // Every rank compresses a share of the PNG: the root's encoder is off the critical path.
    t0 = Clock::now();
    stats->file = expand_pattern(scene.output.pattern, in.step, scene.name);
    written = with_context(
        where, write_png_across_ranks(in.comm, 0, buffers->frame, scene.width, scene.height,
                                      scene.output.compression_level, stats->file, in.threads));
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
                                            to_distance, &buffers->frame)
                   : write_image(buffers->frame, scene.output, stats->file, to_distance));
    stats->write_ms = ms_since(t0);
  }
  stats->total_ms = ms_since(t_start);
  return broadcast_status(in.comm, written, 0);
}

// The composited image to the scene's movie (rank 0, before the image file may take the frame
// over) and to its image file. Collective; same status everywhere: the image's error, else the
// movie's (once, when it stopped; later images go on without it).
Status write_scene_image(const ScenePassInputs &in, const SceneConfig &scene, const Camera &camera,
                         Clock::time_point t_start, SceneBuffers *buffers, SceneStats *stats) {
  if (!scene.output.movie.enabled)
    return write_image_file(in, scene, camera, t_start, buffers, stats);
  int rank = 0;
  MPI_Comm_rank(in.comm, &rank);
  const Status movie =
      rank == 0 ? guarded_status(
                      "scenes '" + scene.name + "': movie",
                      [&] { return send_frame_to_movie(scene, buffers->frame, buffers, stats); })
                : Status();
  Status image;
  if (scene.output.images)
    image = write_image_file(in, scene, camera, t_start, buffers, stats);
  else
    stats->total_ms = ms_since(t_start);
  const Status movie_everywhere = broadcast_status(in.comm, movie, 0);
  return image.ok() ? movie_everywhere : image;
}

}  // namespace

Status run_scene_pass(const ScenePassInputs &in, const SceneConfig &scene, SceneBuffers *buffers,
                      SceneStats *stats) {
  const auto t_start = Clock::now();
  stats->name = scene.name;
  // The colours' scalar range: the same on every rank (from the reduced extent), updated on
  // every rank at every scheduled step so that the remembered ranges stay in step.
  const std::optional<std::array<double, 2>> color_range =
      buffers->color_range.update(scene.color, scalar_range_of(in.global));
  if (scene.color.by == ColorBy::kScalar) stats->color_range = color_range;

  // Every rank has the same inputs here, so these outcomes agree without communication.
  auto t0 = Clock::now();
  Camera camera;
  const RadiusRule radius = radius_rule(scene, *in.particles);  // for every stage below
  const double max_radius = radius.max_radius(in.global);
  const glm::dvec3 lo{in.global.lo[0], in.global.lo[1], in.global.lo[2]};
  const glm::dvec3 hi{in.global.hi[0], in.global.hi[1], in.global.hi[2]};
  const std::string where = "scenes '" + scene.name + "': ";
  const RadiusSource radius_source =
      radius.wanted ? RadiusSource::kParticles : RadiusSource::kConfig;
  // Super-sampling renders the same frustum at s times the width and height (an s x s grid of
  // samples per pixel, core/finish/sample_downsampling.h); every stage up to compositing sees
  // sample pixels.
  const int s_axis = scene.samples_per_axis();
  if (s_axis == 1 && !buffers->samples.rgba.empty())
    buffers->samples = Frame();  // a live change back to 1 sample frees the sample frame
  stats->samples = scene.samples;
  stats->sample_width = scene.width * s_axis;
  stats->sample_height = scene.height * s_axis;
  // A moving camera is where its path puts it at this step.
  const CameraConfig camera_config = camera_settings(scene, in.step);
  if (Status s = make_camera(camera_config, lo, hi, max_radius, scene.width * s_axis,
                             scene.height * s_axis, &camera, radius_source);
      !s.ok())
    return with_context(where, std::move(s));
  stats->camera_ms = ms_since(t0);
  if (camera.point_bounds && !buffers->warned_point_bounds) {
    buffers->warned_point_bounds = true;
    int rank = 0;
    MPI_Comm_rank(in.comm, &rank);
    if (rank == 0)
      std::fprintf(stderr,
                   "lantern: warning: scenes '%s': step %lld: every particle is at one point "
                   "(%g, %g, %g) with radius %g; the automatic camera frames a sphere of radius "
                   "%g around it (warned once)\n",
                   scene.name.c_str(), static_cast<long long>(in.step), 0.5 * (lo.x + hi.x),
                   0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z), max_radius,
                   kMinFramedExtent * std::max(1.0, glm::length(0.5 * (lo + hi))));
  }

  // Every rank has the same camera and bounds: the same answer everywhere, said by rank 0.
  if (!buffers->warned_single_precision) {
    const std::string problem = single_precision_problem(scene, camera, lo, hi, max_radius);
    if (!problem.empty()) {
      buffers->warned_single_precision = true;
      int rank = 0;
      MPI_Comm_rank(in.comm, &rank);
      if (rank == 0)
        std::fprintf(stderr, "lantern: warning: scenes '%s': step %lld: %s (warned once)\n",
                     scene.name.c_str(), static_cast<long long>(in.step), problem.c_str());
    }
  }

  // Object-space ambient occlusion: a density volume reduced over every rank (collective, so
  // before anything a rank may skip); colours are scaled as particles are drawn.
  const bool object_ao = scene.ambient_occlusion.enabled &&
                         scene.ambient_occlusion.method == AmbientOcclusionMethod::kObject;
  OcclusionVolume &occlusion = buffers->occlusion;
  if (!object_ao) occlusion = OcclusionVolume();  // a live change to no object AO frees it
  if (object_ao) {
    t0 = Clock::now();
    const double radius_ao =
        scene.ambient_occlusion.radius.value_or(kDefaultAoRadiusInSphereRadii * max_radius);
    if (Status s = occlusion.build(in.comm, *in.particles, in.global, scene.cuts, radius_ao,
                                   scene.ambient_occlusion.strength, in.threads,
                                   scene.ambient_occlusion.max_nodes);
        !s.ok())
      return with_context(where, std::move(s));
    // With the deposit the refit streamed the positions into (OcclusionVolume::arm_tap).
    stats->cues_ms = ms_since(t0) + occlusion.last_tap_ms();
    stats->ao_deposit = occlusion.last_build_tapped() ? "refit" : "own";
    stats->ao_nodes = occlusion.node_counts();
    stats->ao_spacing = occlusion.node_spacing();
  }

  // Every stage's values, resolved once from the configuration; the passes hand each its part.
  // The colours use this frame's range (fixed, or remembered across steps).
  SceneSettings settings = scene_settings(scene);
  settings.shading.color.range = color_range;
  settings.finish.cues.threads = in.threads;
  settings.image_band_rows = image_band_rows(in.comm, scene, settings);
  buffers->image_band.reset();
  Status local = check_scene_needs(scene, radius, *in.particles, in.bonds);
  if (scene.style == SceneStyle::kDensity) {
    if (Status s = run_density_scene(in, settings, where, camera, radius, std::move(local), buffers,
                                     stats);
        !s.ok())
      return s;
    if (Status s = draw_scene_overlays(in, settings, camera, scene, buffers, stats); !s.ok())
      return s;
    return write_scene_image(in, scene, camera, t_start, buffers, stats);
  }
  // The screen-space cues read view depths through the final image's camera: with
  // super-sampling the sample frame's has s times the pixels (the same frustum, so the same
  // depths).
  Camera image_camera = camera;
  if (s_axis > 1 && wants_screen_cues(settings.finish.cues))
    (void)make_camera(camera_config, lo, hi, max_radius, scene.width, scene.height, &image_camera,
                      radius_source);  // succeeded above at s times the size
  if (Status s = run_sphere_scene(in, settings, where, camera, image_camera, radius,
                                  object_ao ? &occlusion : nullptr, std::move(local), t_start,
                                  buffers, stats);
      !s.ok())
    return s;
  if (Status s = draw_scene_overlays(in, settings, camera, scene, buffers, stats); !s.ok())
    return s;
  return write_scene_image(in, scene, camera, t_start, buffers, stats);
}

}  // namespace lantern
