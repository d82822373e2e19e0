// Thermodynamic output: temperature, energies per atom and the virial pressure, reduced over
// ranks, and their one-line text form.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>

#include "atoms.h"
#include "lj_force.h"

namespace mini_md {

struct ThermoState {
  int64_t step = 0;
  double temperature = 0.0;  // 2 KE / (3N - 3)
  double pe_atom = 0.0;
  double ke_atom = 0.0;
  double etot_atom = 0.0;
  double pressure = 0.0;  // (2 KE + virial) / (3 V)
  // E/atom with U shifted to 0 at the cutoff, whatever the display convention: the quantity
  // velocity Verlet conserves up to its O(dt^2) error, used for blow-up checks and the dt sweep.
  double e_conserved_atom = 0.0;
};

// Collective. `pairs` is this rank's tally from a force call with energies; `energy_shift` is
// the per-pair shift already in pairs.energy (U(rc) or 0) and `cutoff_energy` is U(rc).
ThermoState reduce_thermo(const Atoms &atoms, const PairTally &pairs, int64_t natoms, double volume,
                          double energy_shift, double cutoff_energy, MPI_Comm comm, int64_t step);

std::string thermo_header();
std::string format_thermo(const ThermoState &t);

}  // namespace mini_md
