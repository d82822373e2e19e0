// One scene on one scheduled step, on every rank: camera, the spheres to draw, rendering,
// compositing across ranks, and the image file on rank 0. Collective over the communicator.
#pragma once

#include <mpi.h>

#include <vector>

#include "core/bricks/brick_cache.h"
#include "core/common/status.h"
#include "core/config/config.h"
#include "core/culling/brick_cut_counts.h"
#include "core/culling/brick_selection.h"
#include "core/culling/cull_stage.h"
#include "core/output/background_image_writer.h"
#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"
#include "core/pipeline/scene_stats.h"
#include "core/render/cpu_sphere_pass.h"
#include "core/render/density_splat.h"
#include "core/render/sphere_renderer.h"
#include "core/view/frame.h"

namespace lantern {

// What the scenes of one context share and keep between steps; owned by the Runtime.
struct PassScratch {
  BrickCache bricks;         // this step's bricks, refit on later steps
  BrickSelection selection;  // the visible bricks of the scene being drawn
  Culler culler;             // per-particle culling for OpenGL (pyramids, grids reused)
  CpuSpherePass cpu_pass;    // culling and drawing in one pass for the CPU renderer
  DrawList draw;             // its lists are released once drawn
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
  // Gather the per-rank spread of drawn, culled and milliseconds (SceneStats::per_rank): one
  // small reduction per scene, run only when the stats line is written. Same on every rank.
  bool per_rank_stats = false;
  int threads = 1;                // for this rank's bricks, scan and CPU raster (`threads:`)
  const Extent *local = nullptr;  // this rank's own scan (before the reduction), when known
};

// The brick options of a step: the rank's threads and, when known, its scan (saves a pass).
inline BrickOptions brick_options(const ScenePassInputs &in) {
  BrickOptions options;
  options.threads = in.threads;
  options.known_extent = in.local;
  return options;
}

struct SceneBuffers {
  std::vector<SphereInstance> instances;
  Frame frame;    // the image (on root after compositing)
  Frame samples;  // samples > 1: the sample-resolution frame, kept between steps like `frame`
  BackgroundImageWriter writer;  // rank 0, with output.asynchronous
  BrickCutCounts cut_counts;     // this scene's cutting planes per brick (edits are incremental)
  DensityImage density;          // style: density - this rank's sums, then (rank 0) all ranks'
};

// Renders `scene` and writes its image. Every rank returns the same status.
Status run_scene_pass(const ScenePassInputs &in, const SceneConfig &scene, SceneBuffers *buffers,
                      SceneStats *stats);

}  // namespace lantern
