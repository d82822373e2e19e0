// What one scene cost on one step: stage times (ms) and particle counts, written as part of the
// step's JSON stats line.
#pragma once

#include <mpi.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/composite/composite_cost_model.h"
#include "core/composite/depth_compositor.h"
#include "core/culling/cull_stats.h"
#include "core/output/movie/movie_writer.h"
#include "core/pipeline/rank_spread.h"
#include "core/pipeline/render_budget.h"

namespace lantern {

// Compositing on every rank (with stats on): what moved, spread over the ranks. JSON "composite".
struct CompositeSummary {
  std::string schedule;  // active pixels: the schedule run ("binary_swap", "radix_k 4x2", ...)
  double model_ms = 0;   // the cost model's estimate for the busiest rank
  std::optional<CompositeCostModel> model;  // the model the schedule was chosen by, if any
  // Per rank: bytes and messages handed to MPI and received, active pixels before compositing,
  // and the CPU time of the rank's own compositing work (scan, encode, merge; not MPI waits).
  RankSpread bytes_sent, bytes_received, messages_sent, messages_received, active_pixels,
      work_cpu_ms;
  nlohmann::json to_json() const;
};

// Collective over comm: the spread of this rank's compositing statistics, at rank 0.
CompositeSummary summarize_composite(MPI_Comm comm, const CompositeStats &local,
                                     const CompositeCostModel *model);

// A scene's movie on one step (rank 0): JSON "movie".
struct SceneMovieStats {
  MovieProgress progress;  // after this step's frame was handed over
  double submit_ms = 0.0;  // this step's cost: copying the frame into the queue (and any wait)
  bool behind = false;     // this step's frame was dropped, or the step waited for the encoder
};

struct SceneStats {
  std::string name;
  // Milliseconds per stage, measured on rank 0 (the rank that also writes the file). cull_ms
  // includes building the step's bricks in the first scene of a step (later scenes reuse them).
  double bricks_ms = 0;  // part of cull_ms: building (or refitting) this step's bricks
  std::string bricks;    // "built", "refit" (kept z-order, new bounds) or "cached" (same step)
  // Object-space ambient occlusion's deposit (rank 0's): "refit" where it shared the bricks'
  // refit's read of the positions (OcclusionVolume::arm_tap), "own" where it read them itself;
  // "" without object AO.
  std::string ao_deposit;
  // Its volume's nodes per axis and their spacing (simulation units): farther apart than radius / 2
  // where `max_nodes` capped it (with object AO only).
  std::array<int, 3> ao_nodes{0, 0, 0};
  double ao_spacing = 0.0;
  double camera_ms = 0, cull_ms = 0, instances_ms = 0, draw_ms = 0, readback_ms = 0,
         composite_ms = 0, write_ms = 0, total_ms = 0;
  // Depth cues: object AO's density volume plus the screen-space cues after
  // compositing (0 when none is on).
  double cues_ms = 0;
  // Particle counts summed over ranks.
  int64_t drawn = 0;     // spheres sent to the renderer
  int64_t splatted = 0;  // sub-pixel spheres written by the CPU point path (lod.point_path)
  int64_t culled = 0;    // finite particles dropped by culling or level of detail
  // ... of which: outside the frustum, beyond a cutting plane, left out by level of detail, and
  // hidden (occlusion culling).
  int64_t frustum_culled = 0, cut_culled = 0, lod_dropped = 0, occlusion_culled = 0;
  std::string composite_method;
  std::string renderer;   // "cpu" (CPU raster) or "opengl"
  std::string occlusion;  // occlusion mode run (and why, for auto), as rank 0 decided it
  std::string file;       // the image written
  // samples: rays per pixel, and the frame every stage before down-sampling drew (sample pixels);
  // downsample_ms: the distributed down-sampling after compositing (0 with samples 1).
  int samples = 1;
  int sample_width = 0, sample_height = 0;
  double downsample_ms = 0;
  // Overlays (box, labels, legend, axes) drawn on rank 0; JSON ms.overlays, only for a scene
  // that has them.
  std::optional<double> overlays_ms;
  // How drawn, culled and the ranks' own milliseconds spread over the ranks (rank 0; with stats
  // on): JSON "per_rank".
  std::optional<PerRankStats> per_rank;
  // occlusion: probabilistic: iterations and samples (the slowest rank), meshlets per class and
  // particles culled (summed over ranks). JSON "probabilistic".
  std::optional<ProbabilisticStats> probabilistic;
  // Scenes with bonds: half-bonds (two per bond) drawn and culled, summed over ranks. JSON
  // "bonds".
  std::optional<BondCounts> bonds;
  // Compositing's traffic over the ranks (rank 0; with stats on, two or more ranks).
  std::optional<CompositeSummary> composite;
  // output.movie: JSON "movie" {file, encoder, frames, queued, dropped, behind, ...}.
  std::optional<SceneMovieStats> movie;
  // color.by: scalar: the scalar range this frame's colours used (color.range). JSON
  // "color_range": [lo, hi].
  std::optional<std::array<double, 2>> color_range;
  // budget_ms / budget_percent: the budget, the settings chosen, the measured time and the
  // error estimate of the choice. JSON "budget".
  std::optional<BudgetStats> budget;

  nlohmann::json to_json() const;
  // One line for a log: the per-rank spread, e.g. "scene 'a' per rank: drawn 10..30 (imbalance
  // 1.50, max on rank 2), culled ..., ms ..."; "" without per-rank statistics.
  std::string per_rank_line() const;

 private:
  nlohmann::json counts_json() const;  // everything but per_rank
};

// Sums this rank's particle counts (`local`: drawn, splatted, and culled by frustum, cutting
// planes, level of detail and occlusion) over the ranks of comm into *stats. Collective: one
// reduction; every rank gets the sums.
void sum_counts_over_ranks(MPI_Comm comm, const CullStats &local, SceneStats *stats);
// The same for the half-bond counts, into stats->bonds. Collective: one reduction.
void sum_bond_counts_over_ranks(MPI_Comm comm, const BondCounts &local, SceneStats *stats);

}  // namespace lantern
