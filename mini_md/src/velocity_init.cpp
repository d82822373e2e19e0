#include "velocity_init.h"

#include <cmath>

#include "counter_rng.h"

namespace mini_md {

double global_kinetic_energy(const Atoms &atoms, MPI_Comm comm) {
  double ke = 0.0;
  for (int i = 0; i < atoms.nlocal; ++i) {
    const Vec3 &v = atoms.v[i];
    ke += 0.5 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  MPI_Allreduce(MPI_IN_PLACE, &ke, 1, MPI_DOUBLE, MPI_SUM, comm);
  return ke;
}

void create_velocities(Atoms &atoms, double temperature, uint64_t seed, MPI_Comm comm) {
  // local momentum (3) and count (1)
  double sums[4] = {0, 0, 0, 0};
  for (int i = 0; i < atoms.nlocal; ++i) {
    const uint64_t key = static_cast<uint64_t>(atoms.id[i]);
    for (int d = 0; d < 3; ++d) {
      atoms.v[i][d] = gaussian(seed, key, d);
      sums[d] += atoms.v[i][d];
    }
    sums[3] += 1.0;
  }
  // The sum order differs between rank counts, so the mean (and the scale below) agree across
  // rank counts to round-off, not bitwise.
  MPI_Allreduce(MPI_IN_PLACE, sums, 4, MPI_DOUBLE, MPI_SUM, comm);
  const double natoms = sums[3];
  if (natoms == 0) return;
  for (int i = 0; i < atoms.nlocal; ++i) {
    for (int d = 0; d < 3; ++d) atoms.v[i][d] -= sums[d] / natoms;
  }
  const double dof = 3.0 * natoms - 3.0;
  const double ke = global_kinetic_energy(atoms, comm);
  const double scale = (ke > 0 && dof > 0) ? std::sqrt(temperature * dof / (2.0 * ke)) : 0.0;
  for (int i = 0; i < atoms.nlocal; ++i) {
    for (int d = 0; d < 3; ++d) atoms.v[i][d] *= scale;
  }
}

}  // namespace mini_md
