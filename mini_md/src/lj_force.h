// Lennard-Jones 12-6 pair forces, epsilon = sigma = 1:
//   U(r) = 4 (r^-12 - r^-6) for r < cutoff, 0 beyond.
// By default the potential is NOT shifted (U jumps by 4(rc^-12 - rc^-6) = -0.0163 at rc = 2.5),
// matching LAMMPS pair_style lj/cut without pair_modify shift, so step-0 energies compare with
// LAMMPS. `energy_shift` (= U(rc) for a shifted potential, else 0) is subtracted per pair inside
// the cutoff; forces never change.
#pragma once

#include "atoms.h"
#include "neighbor_list.h"

namespace mini_md {

// Sums over this rank's pairs; the global values are the sums over ranks.
struct PairTally {
  double energy = 0.0;  // sum of U over pairs
  double virial = 0.0;  // sum of r . f over pairs (pressure = (2 KE + virial) / 3V)
  double inside = 0.0;  // pairs within the cutoff: energy + inside * shift switches conventions
};

// Zeroes owned and ghost forces and accumulates the pair forces of the half list (Newton's
// third law: f[j] gets -f_ij, including ghosts j). Energy and virial only if `tally`, since the
// extra work is wasted on steps without thermo output.
PairTally compute_lj_forces(Atoms &atoms, const NeighborList &list, double cutoff,
                            double energy_shift, bool tally);

// U(rc) = 4 (rc^-12 - rc^-6): the shift that makes the potential continuous at the cutoff.
double lj_energy_at(double r);

// The same with the force magnitude capped for r < r_cap (its value at r_cap), so that
// overlapping or coincident atoms get a finite, bounded push. Used only by --relax.
// Coincident atoms are pushed apart along a direction derived from their ids.
PairTally compute_capped_lj_forces(Atoms &atoms, const NeighborList &list, double cutoff,
                                   double r_cap);

}  // namespace mini_md
