// Vec3: one xyz triple. Per-atom vectors are stored as std::vector<Vec3>, i.e. interleaved
// x[N][3] doubles, the layout LAMMPS and most MD codes use: the three components of an atom share
// a cache line, which is what the pair loop touches together.
#pragma once

#include <array>

namespace mini_md {

using Vec3 = std::array<double, 3>;
static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 must be a packed xyz triple");

}  // namespace mini_md
