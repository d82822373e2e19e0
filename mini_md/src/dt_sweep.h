// The dt sweep: the same NVE run (lattice melt by default) for several time steps over a fixed
// simulated time, reporting energy drift per atom against wall time, so a user can pick dt.
#pragma once

#include <mpi.h>

#include <string>
#include <vector>

#include "run_config.h"

namespace mini_md {

struct SweepRow {
  double dt = 0.0;
  int64_t steps = 0;
  int64_t atoms = 0;
  double drift_atom = 0.0;    // E/atom(end) - E/atom(0)
  double max_dev_atom = 0.0;  // max |E/atom(t) - E/atom(0)| over the sampled steps
  double seconds = 0.0;       // wall time of the stepping loop
  bool stable = true;         // false: the run stopped on a blow-up
  std::string note;           // the blow-up message, if any
};

// Collective. Thermostat settings of `base` are ignored (NVE by definition).
std::vector<SweepRow> run_dt_sweep(const RunConfig &base, const std::vector<double> &dts,
                                   double sim_time, MPI_Comm comm);

std::string format_sweep_table(const std::vector<SweepRow> &rows, double sim_time);
std::string format_sweep_csv(const std::vector<SweepRow> &rows);

}  // namespace mini_md
