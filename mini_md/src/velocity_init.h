// Initial velocities: a Gaussian per component keyed by the atom's global id (its lattice index
// + 1), then zero total momentum and an exact rescale to the requested temperature with 3N - 3
// degrees of freedom (the LAMMPS convention). Same state for any rank count.
#pragma once

#include <mpi.h>

#include <cstdint>

#include "atoms.h"

namespace mini_md {

// Overwrites the velocities of all owned atoms. Collective.
void create_velocities(Atoms &atoms, double temperature, uint64_t seed, MPI_Comm comm);

// Kinetic energy sum over all ranks: sum 1/2 v^2.
double global_kinetic_energy(const Atoms &atoms, MPI_Comm comm);

}  // namespace mini_md
