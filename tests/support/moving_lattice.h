// Test support: this rank's slab of a 64 x 64 x 64 lattice of points one unit apart (x fastest,
// as an MD code's sorted arrays hold a crystal: runs of consecutive indices per brick), 262 144
// points over all ranks of MPI_COMM_WORLD, moved for `step`: step 0 not at all, step 1 and later
// a little (a wobble under a tenth of the spacing that changes with the step), step 2 and later
// also a few (one in 997) far along x. Packed x y z doubles; for pipeline tests over steps that
// build the bricks, refit them and repair them.
#pragma once

#include <cmath>
#include <vector>

#include "tests/support/mpi_world.h"

namespace lantern::testing {

// `rank` of `ranks`: the slab of another split (rank 0 of 1: the whole lattice).
inline std::vector<double> moving_lattice(int step, int rank = world_rank(),
                                          int ranks = world_size()) {
  const int n = 64;
  std::vector<double> xyz;
  for (int z = n * rank / ranks; z < n * (rank + 1) / ranks; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double i = double((z * n + y) * n + x);
        double p[3] = {double(x), double(y), double(z)};
        if (step >= 1)
          for (int c = 0; c < 3; ++c) p[c] += 0.05 * std::sin(0.37 * i + 1.3 * c + step);
        if (step >= 2 && ((z * n + y) * n + x) % 997 == 0) p[0] += 30.0;
        xyz.insert(xyz.end(), {p[0], p[1], p[2]});
      }
  return xyz;
}

}  // namespace lantern::testing
