#include "langevin.h"

#include <cmath>

#include "counter_rng.h"

namespace mini_md {

void apply_langevin(Atoms &atoms, double temperature, double damp, double dt, uint64_t seed,
                    int64_t step) {
  const double gamma1 = -1.0 / damp;
  const double gamma2 = std::sqrt(24.0 * temperature / (damp * dt));
  // A distinct stream from the initial velocities, which use `seed` itself.
  const uint64_t noise_seed = mix64(seed ^ 0x4C414E47ull);
  for (int i = 0; i < atoms.nlocal; ++i) {
    const uint64_t key = static_cast<uint64_t>(atoms.id[i]);
    for (int d = 0; d < 3; ++d) {
      const double u = uniform01(noise_seed, key, static_cast<uint64_t>(step) * 3 + d);
      atoms.f[i][d] += gamma1 * atoms.v[i][d] + gamma2 * (u - 0.5);
    }
  }
}

}  // namespace mini_md
