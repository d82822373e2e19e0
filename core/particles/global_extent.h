// Per-frame quantities every rank must agree on: the bounds of the particles (for automatic
// cameras) and the range of the coloring scalar (for automatic colormaps).
//
// Each rank accumulates an Extent over the particles it owns, then reduce_extent() combines them
// with one MPI_Allreduce(MIN) and one MPI_Allreduce(SUM), so every rank gets the same result and
// therefore the same camera and colors.
//
// Empty is neutral: a default Extent has lo = +inf, hi = -inf, max_radius = -inf,
// scalar_min = +inf, scalar_max = -inf and zero counts, so an empty rank changes nothing. If
// every rank is empty the result is still that neutral Extent: empty() is true (finite_count ==
// 0) and the caller must fall back to a default camera; has_scalar_range() is false whenever no
// finite scalar was seen anywhere.
#pragma once

#include <mpi.h>

#include <array>
#include <cstdint>
#include <limits>

namespace lantern {

struct Extent {
  static constexpr double kInf = std::numeric_limits<double>::infinity();

  std::array<double, 3> lo{kInf, kInf, kInf};     // min x, y, z of finite positions
  std::array<double, 3> hi{-kInf, -kInf, -kInf};  // max x, y, z of finite positions
  double max_radius = -kInf;                      // largest finite radius of finite particles
  double scalar_min = kInf;                       // finite scalars of finite particles
  double scalar_max = -kInf;
  int64_t finite_count = 0;     // particles with a finite position
  int64_t nonfinite_count = 0;  // particles skipped for a NaN or infinite coordinate

  bool empty() const { return finite_count == 0; }
  bool has_scalar_range() const { return scalar_min <= scalar_max; }

  // Adds one particle; a non-finite position only counts in nonfinite_count (and its radius and
  // scalar are ignored). Returns whether the particle counted as finite, so the caller can
  // add_scalar() for it.
  bool add_particle(double x, double y, double z, double radius);
  // Adds the coloring scalar of a finite particle; NaN and infinities are ignored.
  void add_scalar(double value);
};

// The union of two extents (what reduce_extent computes across ranks).
Extent merge_extents(const Extent &a, const Extent &b);

// Collective over comm: every rank passes its local extent and gets the global one.
Extent reduce_extent(MPI_Comm comm, const Extent &local);

}  // namespace lantern
