// Langevin thermostat (as LAMMPS fix langevin): f += -v/damp + sqrt(24 kT / (damp dt)) (u - 1/2)
// per component, u uniform in (0,1). The noise for atom `id` at `step` is a pure function of
// (seed, id, step), so a thermostatted run does not depend on the rank count either.
#pragma once

#include <cstdint>

#include "atoms.h"

namespace mini_md {

void apply_langevin(Atoms &atoms, double temperature, double damp, double dt, uint64_t seed,
                    int64_t step);

}  // namespace mini_md
