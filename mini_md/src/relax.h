// --relax: force-capped steepest descent for starts with overlapping or coincident atoms
// (random placement). Pair forces are capped at their value at r_cap and every atom moves at most
// max_move per iteration, so no force or step is ever infinite; the neighbour list is rebuilt
// whenever an atom moved skin/2. Stops when every |f| < fmax or after max_iterations.
#pragma once

#include "simulation.h"

namespace mini_md {

struct RelaxResult {
  int iterations = 0;
  double max_force = 0.0;  // largest capped |f| at the end
  double pe_atom = 0.0;    // capped potential energy per atom at the end
  bool converged = false;
};

RelaxResult relax_positions(Simulation &sim, int max_iterations, double fmax);

}  // namespace mini_md
