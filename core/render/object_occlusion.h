// Object-space ambient occlusion (issue 13; Grottel et al. 2012's idea on seed 004's coarse
// particle density volume): one darkening factor per particle, from how crowded the space around
// it is, applied to its colour before drawing, so the CPU raster and OpenGL both show it and it
// does not depend on the view.
//
// The volume: cubic cells of side `cell` (the ambient_occlusion radius) over the global particle
// bounds, at most kMaxOcclusionCells per axis (cells grow beyond that). Every rank counts its
// drawn particles (kept by the mask, not cut away by an enabled cut plane) per cell; the integer
// counts are summed over ranks with MPI_Allreduce, so the volume - and every factor - is the same
// for any split of the particles. A particle's occupancy o is the mean count of the 3 x 3 x 3
// cells around it (interpolated trilinearly between cell centres, so it varies smoothly from
// particle to particle) divided by the largest count of any cell (1 deep inside a solid, about
// 2/3 on a flat face, less on edges and corners, more in creases and pits); its colour is scaled
// by 1 - strength x clamp(2 o - 1, 0, 1): open corners and edges keep their colour, faces dim a
// little, concave and buried particles darken most. Factors are computed on demand, for the
// particles actually drawn.
//
// Units: simulation lengths. Ownership: a value. Thread-safety: factor() is const and may run
// on several threads at once.
#pragma once

#include <mpi.h>

#include <array>
#include <vector>

#include <glm/vec3.hpp>

#include "core/common/status.h"
#include "core/config/config.h"
#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"

namespace lantern {

inline constexpr int kMaxOcclusionCells = 64;

class OcclusionVolume {
 public:
  // Collective over comm: counts this rank's drawn particles and sums the counts over ranks.
  // Returns OK or kMpi (the same on every rank).
  Status build(MPI_Comm comm, const ParticleArrays &particles, const Extent &global,
               const std::vector<CutPlane> &cuts, double cell, double strength);

  // The colour factor in [1 - strength, 1] of a particle at x (a drawn one: inside the bounds).
  float factor(const glm::dvec3 &x) const;

 private:
  size_t index(int x, int y, int z) const {
    return (size_t(z) * size_t(n_[1]) + size_t(y)) * size_t(n_[0]) + size_t(x);
  }
  void set_grid(const Extent &global, double cell);
  void sum_neighbourhoods(const std::vector<int32_t> &counts);

  glm::dvec3 lo_{0.0};
  double cell_ = 1.0, strength_ = 0.0, full_ = 1.0;  // full_: 27 x the fullest cell's count
  std::array<int, 3> n_{1, 1, 1};
  std::vector<float> sums_;  // 3 x 3 x 3 neighbourhood counts per cell
};

}  // namespace lantern
