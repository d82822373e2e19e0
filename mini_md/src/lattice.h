// The fcc lattice: site positions and their global indices. Every rank enumerates the same
// global sites and keeps those inside its subdomain, so the initial state (and each site's index,
// which seeds its velocity) is the same for any rank count.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "vec3.h"

namespace mini_md {

// Lattice constant of an fcc lattice with 4 atoms per cubic cell at number density `density`.
inline double fcc_lattice_constant(double density) {
  return std::cbrt(4.0 / density);
}

// A block of nx*ny*nz fcc unit cells with lattice constant a, its first corner at `origin`.
struct FccBlock {
  double a = 1.0;
  Vec3 origin{0, 0, 0};
  int n[3] = {1, 1, 1};

  int64_t site_count() const { return int64_t{4} * n[0] * n[1] * n[2]; }
};

inline constexpr double kFccBasis[4][3] = {
    {0.0, 0.0, 0.0}, {0.5, 0.5, 0.0}, {0.5, 0.0, 0.5}, {0.0, 0.5, 0.5}};

// Calls visit(position, global_site_index) for every site of `block` inside [lo, hi).
// Only the unit cells that can overlap [lo, hi) are visited, so the cost is per-rank.
template <typename Visit>
void for_each_fcc_site(const FccBlock &block, const Vec3 &lo, const Vec3 &hi, Visit &&visit) {
  int first[3], last[3];
  for (int d = 0; d < 3; ++d) {
    const double u_lo = (lo[d] - block.origin[d]) / block.a;
    const double u_hi = (hi[d] - block.origin[d]) / block.a;
    first[d] = std::max(0, static_cast<int>(std::floor(u_lo)) - 1);
    last[d] = std::min(block.n[d] - 1, static_cast<int>(std::ceil(u_hi)));
  }
  for (int k = first[2]; k <= last[2]; ++k) {
    for (int j = first[1]; j <= last[1]; ++j) {
      for (int i = first[0]; i <= last[0]; ++i) {
        const int64_t cell = (int64_t{k} * block.n[1] + j) * block.n[0] + i;
        for (int b = 0; b < 4; ++b) {
          const Vec3 p{block.origin[0] + (i + kFccBasis[b][0]) * block.a,
                       block.origin[1] + (j + kFccBasis[b][1]) * block.a,
                       block.origin[2] + (k + kFccBasis[b][2]) * block.a};
          if (p[0] >= lo[0] && p[0] < hi[0] && p[1] >= lo[1] && p[1] < hi[1] && p[2] >= lo[2] &&
              p[2] < hi[2]) {
            visit(p, cell * 4 + b);
          }
        }
      }
    }
  }
}

}  // namespace mini_md
