// Detection of unsafe states. Both checks are collective and end in an MdError thrown on every
// rank whose message names the step, one offending atom and a remedy, so a blown-up run never
// continues silently and never hangs half the ranks.
#pragma once

#include <mpi.h>

#include <cstdint>

#include "atoms.h"
#include "thermo.h"

namespace mini_md {

// Call when any rank saw a non-finite position, velocity or force: finds the atom with the
// smallest id among those with a non-finite x, v or f and throws.
[[noreturn]] void raise_nonfinite(const Atoms &atoms, MPI_Comm comm, int64_t step, double dt);

// Call when an atom moved farther than `limit` (cutoff + skin) since the last neighbour build,
// i.e. within one step: pair interactions were certainly missed. Names the fastest atom.
[[noreturn]] void raise_runaway(const Atoms &atoms, MPI_Comm comm, int64_t step, double dt,
                                double displacement, double limit);

// Throws if the conserved E/atom (shifted potential) moved more than `limit` from `e0_atom`
// (NVE runs), naming the fastest atom.
void check_energy_blowup(const Atoms &atoms, MPI_Comm comm, const ThermoState &now, double e0_atom,
                         double limit, double dt);

// Throws if the temperature exceeds `limit` (thermostatted runs, where E is not conserved).
void check_temperature_blowup(const Atoms &atoms, MPI_Comm comm, const ThermoState &now,
                              double limit, double dt);

}  // namespace mini_md
