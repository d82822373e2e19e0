// The frames lantern-bench-composite composites in its scaling mode: one fixed scene - an fcc
// crystal of n^3 cells (4 n^3 atoms) seen from outside - split spatially over the ranks the way an
// MD code decomposes its box (a px x py x pz grid of equal boxes, MPI_Dims_create), each rank
// drawing its own atoms through the pipeline's own drawing path (core/pipeline/rank_draw.h, the
// CPU raster, exact occlusion culling).
#pragma once

#include <mpi.h>

#include <string>

#include "core/view/frame.h"

namespace lantern::bench {

struct SceneFrame {
  Frame frame;          // this rank's frame, at the sample resolution
  long long atoms = 0;  // this rank's atoms
  std::string note;     // one line: the scene and the split
  std::string error;    // "" if drawn
};

// Draws this rank's share of the fcc crystal of `cells`^3 cells at width x height pixels with
// `samples_per_axis` samples per pixel axis (the frame is that many times larger each way).
// Collective over comm (the extent is reduced); on MPI_COMM_SELF it draws every atom (the one-rank
// reference).
SceneFrame draw_fcc_share(MPI_Comm comm, int cells, int width, int height, int samples_per_axis);

}  // namespace lantern::bench
