// lantern-render's spatial split: each rank reads a contiguous share of a frame's rows (cheap,
// contiguous I/O), then the ranks exchange particles so that each ends with one contiguous run of
// the frame's z-order (Morton) curve - the static load balancing of Gao et al. (visibility-culling
// based rendering of large-scale particle data): data patches traversed along a space-filling
// curve and dealt out evenly, so each rank's particles are compact, its bricks tight, and culling
// works per rank. A rank keeps its received particles in the file's row order (a subsequence of
// it), so the published order is the file's order restricted to the rank's region.
//
// The ranks' runs are cut between cells of 1/1024 of the frame's extent per axis (30-bit key
// prefixes), found by counting particles in two rounds (2^18 coarse cells, then 2^12 fine cells
// inside the coarse cells that hold a cut), so the ranks' counts differ by at most about one fine
// cell's particles. Particles with a NaN or infinite coordinate have no place on the curve and
// stay where they were read (Lantern skips them anyway).
//
// Collective over comm. Thread-safety: one call at a time per communicator.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>

#include "core/dump/particle_frame.h"

namespace lantern {

struct SplitStats {
  int64_t least = 0, most = 0;  // particles per rank after the split
  double mean = 0.0;
  double imbalance() const { return mean > 0.0 ? double(most) / mean : 1.0; }
};

// Replaces *frame (this rank's rows) by this rank's run of the curve. "" or an error message (the
// same on every rank). Fills *stats on every rank.
std::string split_spatially(MPI_Comm comm, ParticleFrame *frame, SplitStats *stats);

}  // namespace lantern
