// Velocity-Verlet (m = 1): the two half kicks around the drift, plus reflecting walls on
// non-periodic axes. Each pass also gathers what the step's safety checks need, so the checks
// cost no extra sweep over memory.
#pragma once

#include "atoms.h"
#include "box.h"

namespace mini_md {

struct DriftReport {
  double max_displacement2 = 0.0;  // largest |x - x_build|^2 of an owned atom (if measured)
  bool finite = true;              // all positions finite
};

// v += dt/2 f; x += dt v; reflect at walls (position mirrored, normal velocity reversed).
DriftReport initial_integrate(Atoms &atoms, const Box &box, double dt, bool measure_displacement);

// v += dt/2 f. Returns whether all velocities are finite (a non-finite force shows up here).
bool final_integrate(Atoms &atoms, double dt);

}  // namespace mini_md
