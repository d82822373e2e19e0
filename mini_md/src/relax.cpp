#include "relax.h"

#include <algorithm>
#include <cmath>

namespace mini_md {

namespace {

constexpr double kCapRadius = 0.9;   // |f| at 0.9 sigma is ~140: large but harmless
constexpr double kMaxMove = 0.05;    // sigma per iteration
constexpr double kMobility = 0.002;  // dx = mobility * f below the cap (stable for LJ stiffness)

double global_max_force(const Atoms &atoms, MPI_Comm comm) {
  double m = 0.0;
  for (int i = 0; i < atoms.nlocal; ++i) {
    const Vec3 &f = atoms.f[i];
    m = std::max(m, f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  }
  MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_MAX, comm);
  return std::sqrt(m);
}

void move_downhill(Atoms &atoms, const Box &box) {
  for (int i = 0; i < atoms.nlocal; ++i) {
    Vec3 dx;
    for (int d = 0; d < 3; ++d) dx[d] = kMobility * atoms.f[i][d];
    const double len = std::sqrt(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
    const double scale = len > kMaxMove ? kMaxMove / len : 1.0;
    for (int d = 0; d < 3; ++d) {
      double c = atoms.x[i][d] + scale * dx[d];
      if (!box.periodic[d]) c = std::clamp(c, box.lo[d], box.hi[d]);
      atoms.x[i][d] = c;
    }
  }
}

}  // namespace

RelaxResult relax_positions(Simulation &sim, int max_iterations, double fmax) {
  RelaxResult result;
  const double half_skin2 = 0.25 * sim.config().skin * sim.config().skin;
  const MPI_Comm comm = sim.domain().comm();
  sim.rebuild();
  for (;;) {
    const PairTally pairs = sim.compute_capped_forces(kCapRadius);
    result.max_force = global_max_force(sim.atoms(), comm);
    double pe = pairs.energy;
    MPI_Allreduce(MPI_IN_PLACE, &pe, 1, MPI_DOUBLE, MPI_SUM, comm);
    result.pe_atom = pe / static_cast<double>(sim.natoms());
    if (result.max_force < fmax) {
      result.converged = true;
      break;
    }
    if (result.iterations >= max_iterations) break;
    move_downhill(sim.atoms(), sim.domain().box());
    ++result.iterations;
    if (sim.global_max_displacement2() > half_skin2) {
      sim.rebuild();
    } else {
      sim.refresh_ghosts();
    }
  }
  return result;
}

}  // namespace mini_md
