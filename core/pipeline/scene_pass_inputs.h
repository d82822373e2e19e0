// What a scene pass works with on one scheduled step: the inputs every scene of the step shares
// (communicator, renderer, particles, their global extent, the step), the scratch the scenes
// share between steps (bricks, culling buffers), and what each scene keeps between steps (its
// frames, image writer, cut counts, density sums, remembered color range, movie). Read by the
// sphere and density scene passes (scene_pass.h, density_scene_pass.h); owned by the Runtime.
#pragma once

#include <mpi.h>

#include <memory>
#include <optional>
#include <string>

#include "core/bricks/brick_bonds.h"
#include "core/bricks/brick_cache.h"
#include "core/color/color_range.h"
#include "core/composite/composite_cost_model.h"
#include "core/culling/brick_cut_counts.h"
#include "core/dump/box.h"
#include "core/finish/finish_image.h"
#include "core/finish/overlays/overlays.h"
#include "core/output/background_image_writer.h"
#include "core/output/movie/movie_writer.h"
#include "core/particles/bond_arrays.h"
#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"
#include "core/particles/periodic_box.h"
#include "core/pipeline/rank_draw.h"
#include "core/pipeline/render_budget.h"
#include "core/render/density_splat.h"
#include "core/render/gl/sphere_renderer.h"
#include "core/render/object_occlusion.h"
#include "core/view/frame.h"

namespace lantern {

// What the scenes of one context share and keep between steps; owned by the Runtime.
struct PassScratch {
  BrickCache bricks;     // this step's bricks, refit on later steps
  BondCache bonds;       // this step's half-bonds by brick, for the scenes that draw bonds
  RankDrawScratch draw;  // selection, culling and drawing buffers (rank_draw.h)
  // Compositing's cost model, measured at the context's first compositing on two or more ranks
  // (composite_cost_model.h) and kept: the same on every rank.
  std::optional<CompositeCostModel> composite_model;
};

// What a scene pass reads and reuses between steps (buffers are kept to avoid reallocation).
struct ScenePassInputs {
  MPI_Comm comm = MPI_COMM_NULL;
  SphereRenderer *renderer = nullptr;  // null without OpenGL: every scene on the CPU raster
  const ParticleArrays *particles = nullptr;
  Extent global;  // reduced over ranks
  int64_t step = 0;
  double time = 0.0;
  PassScratch *scratch = nullptr;
  const BondArrays *bonds = nullptr;          // this rank's published bonds (count 0: none)
  uint64_t bonds_serial = 0;                  // changes with every publication (BondCache)
  const PeriodicBox *periodic_box = nullptr;  // lantern_set_box's, bonds' minimum image; or none
  // Gather the per-rank spread of drawn, culled and milliseconds (SceneStats::per_rank): one
  // small reduction per scene, run only when the stats line is written. Same on every rank.
  bool per_rank_stats = false;
  int threads = 1;                // for this rank's bricks, scan and CPU raster (`threads:`)
  const Extent *local = nullptr;  // this rank's own scan (before the reduction), when known
  // The overlays' simulation box: lantern_set_box's on rank 0 (null: the particles' bounds), and
  // the scalar's name (the legend's default title).
  const Box *box = nullptr;
  std::string scalar_name = "scalar";
};

// The brick options of a step: the rank's threads and, when known, its scan (saves a pass).
inline BrickOptions brick_options(const ScenePassInputs &in) {
  BrickOptions options;
  options.threads = in.threads;
  options.known_extent = in.local;
  return options;
}

struct SceneBuffers {
  Frame frame;  // the image (on root after compositing), or this rank's band of it (image_band)
  // Set when this frame's image was left in row bands (SceneSettings::image_band_rows): the rows
  // this rank holds in `frame`.
  std::optional<ImageBand> image_band;
  Frame samples;    // samples > 1: the sample-resolution frame, kept between steps like `frame`
  Frame cued_band;  // this rank's band of the image while it is finished (kept between steps)
  CueScratch cue_scratch;        // screen cues: AO estimate grids and the distances
  BackgroundImageWriter writer;  // rank 0, with output.asynchronous
  BrickCutCounts cut_counts;     // this scene's cutting planes per brick (edits are incremental)
  DensityImage density;          // style: density - this rank's sums, then (rank 0) all ranks'
  ColorRange color_range;        // the scalar range of the colours, remembered across steps
  OcclusionVolume occlusion;     // ambient_occlusion method object: rebuilt each step, buffers kept
  std::unique_ptr<MovieWriter> movie;    // rank 0, with output.movie (scene_movie.h)
  bool movie_warned = false;             // the "encoder is behind" warning was printed
  bool warned_point_bounds = false;      // rank 0 warned that the camera had a point to frame
  bool warned_single_precision = false;  // rank 0 warned of a scale single precision cannot hold
  std::unique_ptr<OverlayPainter> overlays;  // rank 0, for a scene with overlays
  SceneBudget
      budget;  // budget_ms / budget_percent: the ladder and its controller (render_budget.h)
};

}  // namespace lantern
