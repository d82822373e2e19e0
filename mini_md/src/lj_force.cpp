#include "lj_force.h"

#include <algorithm>
#include <cmath>

#include "counter_rng.h"

namespace mini_md {

namespace {

void zero_forces(Atoms &atoms) {
  std::fill(atoms.f.begin(), atoms.f.end(), Vec3{0, 0, 0});
}

// The hot loop. Templated on kTally so the plain-force variant carries no energy arithmetic.
// i's force accumulates in registers; j's is written at once (j may be a ghost).
template <bool kTally>
PairTally lj_kernel(int nlocal, const Vec3 *__restrict x, Vec3 *__restrict f,
                    const int64_t *__restrict offsets, const int *__restrict neighbors, double cut2,
                    double eshift) {
  double energy = 0.0;
  double virial = 0.0;
  double inside = 0.0;
  for (int i = 0; i < nlocal; ++i) {
    const double xi = x[i][0], yi = x[i][1], zi = x[i][2];
    double fxi = 0.0, fyi = 0.0, fzi = 0.0;
    const int64_t end = offsets[i + 1];
    for (int64_t k = offsets[i]; k < end; ++k) {
      const int j = neighbors[k];
      const double dx = xi - x[j][0];
      const double dy = yi - x[j][1];
      const double dz = zi - x[j][2];
      const double r2 = dx * dx + dy * dy + dz * dz;
      if (r2 < cut2) {
        const double r2inv = 1.0 / r2;
        const double r6inv = r2inv * r2inv * r2inv;
        const double fpair = r6inv * (48.0 * r6inv - 24.0) * r2inv;
        fxi += dx * fpair;
        fyi += dy * fpair;
        fzi += dz * fpair;
        f[j][0] -= dx * fpair;
        f[j][1] -= dy * fpair;
        f[j][2] -= dz * fpair;
        if (kTally) {
          energy += 4.0 * r6inv * (r6inv - 1.0) - eshift;
          virial += r2 * fpair;
          inside += 1.0;
        }
      }
    }
    f[i][0] += fxi;
    f[i][1] += fyi;
    f[i][2] += fzi;
  }
  return PairTally{energy, virial, inside};
}

}  // namespace

double lj_energy_at(double r) {
  const double r6inv = 1.0 / (r * r * r * r * r * r);
  return 4.0 * r6inv * (r6inv - 1.0);
}

PairTally compute_lj_forces(Atoms &atoms, const NeighborList &list, double cutoff,
                            double energy_shift, bool tally) {
  zero_forces(atoms);
  const double cut2 = cutoff * cutoff;
  if (tally) {
    return lj_kernel<true>(atoms.nlocal, atoms.x.data(), atoms.f.data(), list.offsets(),
                           list.neighbors(), cut2, energy_shift);
  }
  return lj_kernel<false>(atoms.nlocal, atoms.x.data(), atoms.f.data(), list.offsets(),
                          list.neighbors(), cut2, energy_shift);
}

PairTally compute_capped_lj_forces(Atoms &atoms, const NeighborList &list, double cutoff,
                                   double r_cap) {
  zero_forces(atoms);
  const double cut2 = cutoff * cutoff;
  const double cap2 = r_cap * r_cap;
  PairTally tally;
  const int64_t *offsets = list.offsets();
  const int *neighbors = list.neighbors();
  for (int i = 0; i < atoms.nlocal; ++i) {
    for (int64_t k = offsets[i]; k < offsets[i + 1]; ++k) {
      const int j = neighbors[k];
      double d[3] = {atoms.x[i][0] - atoms.x[j][0], atoms.x[i][1] - atoms.x[j][1],
                     atoms.x[i][2] - atoms.x[j][2]};
      double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      if (r2 >= cut2) continue;
      if (r2 < 1e-20) {
        // Coincident: no direction exists, so take a fixed one from the two ids (the same on
        // every rank and independent of which atom is i).
        const uint64_t key = static_cast<uint64_t>(std::min(atoms.id[i], atoms.id[j]));
        const double sign = atoms.id[i] < atoms.id[j] ? 1.0 : -1.0;
        for (int c = 0; c < 3; ++c)
          d[c] = sign * (gaussian(key, atoms.id[i] ^ atoms.id[j], c) + 1e-3);
        const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (double &c : d) c *= 1e-10 / norm;
        r2 = 1e-20;
      }
      // Beyond the cap the true force; inside it the force at r_cap along the pair direction.
      const double r2e = std::max(r2, cap2);
      const double r2inv = 1.0 / r2e;
      const double r6inv = r2inv * r2inv * r2inv;
      const double fmag_over_r = r6inv * (48.0 * r6inv - 24.0) * r2inv * std::sqrt(r2e / r2);
      for (int c = 0; c < 3; ++c) {
        atoms.f[i][c] += d[c] * fmag_over_r;
        atoms.f[j][c] -= d[c] * fmag_over_r;
      }
      tally.energy += 4.0 * r6inv * (r6inv - 1.0);
      tally.virial += r2 * fmag_over_r;
    }
  }
  return tally;
}

}  // namespace mini_md
