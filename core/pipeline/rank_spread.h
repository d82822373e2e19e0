// How a per-rank quantity (particles drawn, culled, milliseconds) spreads over the ranks: least,
// greatest, mean, imbalance and the rank holding the greatest - the per-process statistics of
// the nine-spheres paper's Fig. 5, so that load imbalance shows in the stats line.
//
// Plain value types; reduce_rank_spreads is collective.
#pragma once

#include <mpi.h>

#include <vector>

#include <nlohmann/json.hpp>

namespace lantern {

struct RankSpread {
  double min = 0.0, max = 0.0, mean = 0.0;
  int max_rank = 0;  // the lowest-numbered rank holding `max`

  // max over mean: 1 when perfectly balanced, the rank count when one rank has everything; 1 when
  // every rank holds 0 (nothing to balance).
  double imbalance() const { return mean > 0.0 ? max / mean : 1.0; }
  nlohmann::json to_json() const;
};

// The per-rank statistics of one scene on one step.
struct PerRankStats {
  RankSpread drawn;      // spheres each rank sent to its renderer (as the line's `drawn`)
  RankSpread culled;     // the rank's finite particles not drawn
  RankSpread ms;         // the rank's own work before compositing: camera, cull, draw, readback
  RankSpread particles;  // the rank's finite particles: how evenly the host split the data
  nlohmann::json to_json() const;
};

// Collective over comm: one MPI_Reduce (a user-defined operation over four doubles per value)
// brings the spread of this rank's four values to `root`; other ranks get an unspecified value.
PerRankStats reduce_per_rank_stats(MPI_Comm comm, int root, double drawn, double culled, double ms,
                                   double particles);

// The same for any number of values (the same count on every rank): one RankSpread per value, at
// root.
std::vector<RankSpread> reduce_rank_spreads(MPI_Comm comm, int root,
                                            const std::vector<double> &local);

}  // namespace lantern
