#include "integrator.h"

#include <algorithm>
#include <cmath>

namespace mini_md {

namespace {

void reflect(Atoms &atoms, const Box &box) {
  for (int d = 0; d < 3; ++d) {
    if (box.periodic[d]) continue;
    const double lo = box.lo[d], hi = box.hi[d];
    for (int i = 0; i < atoms.nlocal; ++i) {
      double &c = atoms.x[i][d];
      if (c < lo) {
        c = std::min(2 * lo - c, hi);
        atoms.v[i][d] = -atoms.v[i][d];
      } else if (c > hi) {
        c = std::max(2 * hi - c, lo);
        atoms.v[i][d] = -atoms.v[i][d];
      }
    }
  }
}

}  // namespace

DriftReport initial_integrate(Atoms &atoms, const Box &box, double dt, bool measure_displacement) {
  const double half = 0.5 * dt;
  Vec3 *__restrict x = atoms.x.data();
  Vec3 *__restrict v = atoms.v.data();
  const Vec3 *__restrict f = atoms.f.data();
  const int n = atoms.nlocal;
  // A NaN or Inf anywhere makes this sum non-finite; one test instead of 3N.
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    for (int d = 0; d < 3; ++d) {
      v[i][d] += half * f[i][d];
      x[i][d] += dt * v[i][d];
    }
    sum += x[i][0] + x[i][1] + x[i][2];
  }
  if (!(box.periodic[0] && box.periodic[1] && box.periodic[2])) reflect(atoms, box);
  DriftReport report;
  report.finite = std::isfinite(sum);
  if (measure_displacement) {
    const Vec3 *__restrict xb = atoms.x_build.data();
    double m = 0.0;
    for (int i = 0; i < n; ++i) {
      const double dx = x[i][0] - xb[i][0], dy = x[i][1] - xb[i][1], dz = x[i][2] - xb[i][2];
      m = std::max(m, dx * dx + dy * dy + dz * dz);
    }
    report.max_displacement2 = m;
  }
  return report;
}

bool final_integrate(Atoms &atoms, double dt) {
  const double half = 0.5 * dt;
  Vec3 *__restrict v = atoms.v.data();
  const Vec3 *__restrict f = atoms.f.data();
  double sum = 0.0;
  for (int i = 0; i < atoms.nlocal; ++i) {
    for (int d = 0; d < 3; ++d) v[i][d] += half * f[i][d];
    sum += v[i][0] + v[i][1] + v[i][2];
  }
  return std::isfinite(sum);
}

}  // namespace mini_md
