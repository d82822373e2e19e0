// What culling did to one scene on one rank: particle counts by cause and brick counts. Plain
// value type, summed over ranks by the pipeline for the stats line.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>

namespace lantern {

// Ibrahim et al.'s probabilistic culling on one rank (occlusion: probabilistic). Meshlet classes
// after convergence, indexed by OcclusionClass.
struct ProbabilisticStats {
  int64_t iterations = 0;  // until no class changed for `patience` iterations (or the cap)
  int64_t samples = 0;     // depth samples per pixel taken until then (passes)
  int64_t meshlets[4] = {0, 0, 0, 0};  // in classes P, L, M, O (occluded: culled)
  int64_t particles_culled = 0;        // particles of the occluded meshlets
};

// Half-bonds (two per bond) on one rank: those this rank draws, and what became of them.
struct BondCounts {
  int64_t halves = 0;            // half-bonds of this rank's list that it draws
  int64_t frustum_culled = 0;    // outside the view frustum
  int64_t cut_culled = 0;        // their atom on the dropped side of a cutting plane
  int64_t lod_dropped = 0;       // in a brick that level of detail thinned
  int64_t occlusion_culled = 0;  // hidden (exactly: hzb, or the CPU raster's depth)
  int64_t drawn = 0;             // drawn as cylinders
  // Ranks that refit an earlier step's half-bond grouping instead of building it (BondCache).
  int64_t grouping_reused = 0;
};

struct CullStats {
  std::string occlusion;         // the mode run; for auto also why, e.g. "hzb (auto: dense, ...)"
  int64_t candidates = 0;        // finite particles of the rank
  int64_t frustum_culled = 0;    // outside the view frustum
  int64_t cut_culled = 0;        // on the dropped side of a cutting plane
  int64_t lod_dropped = 0;       // left out by level of detail
  int64_t occlusion_culled = 0;  // hidden (hzb: provably; nine_spheres: by the rule)
  int64_t drawn = 0;             // spheres drawn (impostors, or ray-cast by the CPU pass)
  int64_t splatted = 0;          // CPU point path
  int64_t bricks = 0, bricks_outside = 0, bricks_inside = 0, bricks_occluded = 0;
  bool per_particle_frustum = false;  // some brick straddled the frustum
  ProbabilisticStats probabilistic;   // occlusion: probabilistic only
  BondCounts bonds;                   // scenes with bonds only
};

// The probabilistic counts of every rank of comm: the slowest rank's iterations and samples, the
// meshlet classes and culled particles summed. Collective (two small reductions); the same on
// every rank.
ProbabilisticStats reduce_probabilistic_stats(MPI_Comm comm, const ProbabilisticStats &local);

}  // namespace lantern
