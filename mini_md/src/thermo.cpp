#include "thermo.h"

#include <cstdio>

namespace mini_md {

ThermoState reduce_thermo(const Atoms &atoms, const PairTally &pairs, int64_t natoms, double volume,
                          double energy_shift, double cutoff_energy, MPI_Comm comm, int64_t step) {
  double sums[4] = {0.0, pairs.energy, pairs.virial, pairs.inside};
  for (int i = 0; i < atoms.nlocal; ++i) {
    const Vec3 &v = atoms.v[i];
    sums[0] += 0.5 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  MPI_Allreduce(MPI_IN_PLACE, sums, 4, MPI_DOUBLE, MPI_SUM, comm);
  const double n = static_cast<double>(natoms);
  const double dof = 3.0 * n - 3.0;
  ThermoState t;
  t.step = step;
  t.temperature = dof > 0 ? 2.0 * sums[0] / dof : 0.0;
  t.ke_atom = sums[0] / n;
  t.pe_atom = sums[1] / n;
  t.etot_atom = t.ke_atom + t.pe_atom;
  t.pressure = (2.0 * sums[0] + sums[2]) / (3.0 * volume);
  t.e_conserved_atom = t.etot_atom - (cutoff_energy - energy_shift) * sums[3] / n;
  return t;
}

std::string thermo_header() {
  char line[160];
  std::snprintf(line, sizeof line, "%10s %14s %14s %14s %14s %14s", "Step", "Temp", "PE/atom",
                "KE/atom", "E/atom", "Press");
  return line;
}

std::string format_thermo(const ThermoState &t) {
  char line[160];
  std::snprintf(line, sizeof line, "%10lld %14.8g %14.8g %14.8g %14.8g %14.8g",
                static_cast<long long>(t.step), t.temperature, t.pe_atom, t.ke_atom, t.etot_atom,
                t.pressure);
  return line;
}

}  // namespace mini_md
