#include "core/pipeline/sphere_scene_pass.h"

#include <algorithm>
#include <cstdint>
#include <new>
#include <string>
#include <utility>

#include "core/common/collective_status.h"
#include "core/common/ms_since.h"
#include "core/finish/finish_image.h"
#include "core/pipeline/rank_draw.h"
#include "core/pipeline/rank_spread.h"

namespace lantern {
namespace {

// kOutOfMemory naming the scene (`where`) and the size of its frame on this rank.
Status out_of_memory(const FinishSettings &finish, const std::string &where, const char *what) {
  const int64_t s = finish.samples_per_axis;
  const int64_t width = int64_t(finish.width) * s, height = int64_t(finish.height) * s;
  return {StatusCode::kOutOfMemory, where + "out of memory " + what + " " + std::to_string(width) +
                                        " x " + std::to_string(height) + " pixels (" +
                                        std::to_string(width * height * 8) +
                                        " bytes for the frame on this rank)"};
}

}  // namespace

Status run_sphere_scene(const ScenePassInputs &in, const SceneSettings &settings,
                        const std::string &where, const Camera &camera, const Camera &image_camera,
                        const RadiusRule &radius, const OcclusionVolume *occlusion, Status local,
                        std::chrono::steady_clock::time_point t_start, SceneBuffers *buffers,
                        SceneStats *stats) {
  // Super-sampling draws the same frustum at s times the width and height; every stage up to
  // compositing sees sample pixels.
  Frame &frame = settings.finish.samples_per_axis > 1 ? buffers->samples : buffers->frame;
  CullStats cull;
  // This rank's drawing allocates (the frame, bricks, instances): running out of memory here is
  // this rank's failure, agreed below like any other, so no rank skips the collectives alone.
  if (local.ok()) try {
      const auto t0 = std::chrono::steady_clock::now();
      double build_ms = 0.0;
      const BrickSet &bricks = in.scratch->bricks.for_step(
          *in.particles, in.step, brick_options(in), &build_ms, &stats->bricks);
      // The step's half-bonds by brick, built with the bricks (once per step, for every scene).
      const BrickBonds *halves = nullptr;
      if (settings.cull.bonds && in.bonds && in.bonds->count() > 0)
        halves = &in.scratch->bonds.for_step(*in.particles, *in.bonds, in.bonds_serial, bricks,
                                             in.periodic_box, in.step, &build_ms);
      stats->bricks_ms = build_ms;
      // A refit the runtime made ahead of the scan (BrickCache::refit_first) counts as culling.
      const double bricks_wall_ms = ms_since(t0);
      const double ahead_ms = std::max(0.0, build_ms - bricks_wall_ms);
      RankScene rank_scene(*in.particles, bricks, camera, settings, radius);
      rank_scene.bonds = in.bonds;
      rank_scene.bond_halves = halves;
      rank_scene.box = in.periodic_box;
      rank_scene.global = in.global;
      rank_scene.step = in.step;
      rank_scene.renderer = in.renderer;
      rank_scene.occlusion = occlusion;
      rank_scene.cut_counts = &buffers->cut_counts;
      rank_scene.threads = in.threads;
      RankDraw drawn;
      local =
          with_context(where, draw_scene_on_rank(rank_scene, &in.scratch->draw, &frame, &drawn));
      cull = drawn.cull;
      // The CPU pass's list of drawn spheres (kept by draw_scene_on_rank for its callers to read)
      // is not needed past this point: nothing of it is kept between frames.
      PageVector<uint64_t>().swap(in.scratch->draw.draw.spheres);
      if (halves) cull.bonds.grouping_reused = in.scratch->bonds.reused() ? 1 : 0;
      stats->renderer = drawn.renderer;
      stats->occlusion = cull.occlusion;
      // Building (or refitting) the bricks counts as culling.
      stats->cull_ms = bricks_wall_ms + ahead_ms + drawn.cull_ms;
      stats->instances_ms = drawn.instances_ms;
      stats->draw_ms = drawn.draw_ms;
      stats->readback_ms = drawn.readback_ms;
    } catch (const std::bad_alloc &) {
      local = out_of_memory(settings.finish, where, "drawing");
    }
  const double own_ms = ms_since(t_start);  // this rank's work, before waiting on the others
  if (Status s = agree_on_status(in.comm, local); !s.ok()) return s;
  sum_counts_over_ranks(in.comm, cull, stats);
  if (settings.cull.bonds) sum_bond_counts_over_ranks(in.comm, cull.bonds, stats);
  if (settings.cull.occlusion == OcclusionMode::kProbabilistic)  // the same on every rank
    stats->probabilistic = reduce_probabilistic_stats(in.comm, cull.probabilistic);
  stats->culled = in.global.finite_count - stats->drawn - stats->splatted;
  if (in.per_rank_stats)
    stats->per_rank = reduce_per_rank_stats(
        in.comm, 0, double(cull.drawn), double(cull.candidates - cull.drawn - cull.splatted),
        own_ms, in.local ? double(in.local->finite_count) : double(cull.candidates));

  // Compositing's cost model: measured once per context, on every rank alike.
  int ranks = 1;
  MPI_Comm_size(in.comm, &ranks);
  std::optional<CompositeCostModel> &model = in.scratch->composite_model;
  if (ranks > 1 && !model) {
    CompositeCostModel measured;
    if (Status s = measure_cost_model(in.comm, &measured); !s.ok())
      return with_context(where + "compositing: ", std::move(s));
    model = measured;
  }
  // The composited image, finished (down-sampling, screen-space cues): on rank 0, or left in
  // row bands for the PNG writer (the merged frame then never goes through one rank).
  FinishStats finished;
  const CompositeCostModel *cost = model ? &*model : nullptr;
  Status s;
  if (settings.image_band_rows > 0) {
    ImageBand band;
    // The rows end in `frame` (one sample, no cues) or in a band frame that is not it.
    Frame *held = &frame == &buffers->frame ? &buffers->cued_band : &buffers->frame;
    s = finish_image_to_bands(in.comm, frame, settings.finish, image_camera,
                              radius.max_radius(in.global), cost, settings.image_band_rows, held,
                              &band, &finished, &buffers->cue_scratch);
    if (s.ok()) buffers->image_band = band;
  } else {
    s = finish_image(in.comm, frame, settings.finish, image_camera, radius.max_radius(in.global),
                     cost, &buffers->frame, &finished, &buffers->cue_scratch, &buffers->cued_band);
  }
  if (!s.ok()) return with_context(where, std::move(s));
  stats->downsample_ms = finished.downsample_ms;
  stats->cues_ms += finished.cues_ms;
  stats->composite_ms = finished.composite.milliseconds;
  stats->composite_method = finished.composite.method;
  if (in.per_rank_stats && ranks > 1)
    stats->composite = summarize_composite(in.comm, finished.composite, model ? &*model : nullptr);
  return {};
}

}  // namespace lantern
