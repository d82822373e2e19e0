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
// 1/2 on a flat surface, less on edges and corners, more in creases and pits); its colour is
// scaled by 1 - strength x clamp(2 o - 1, 0, 1): open surfaces keep their colour, concave and
// buried ones darken.
//
// Collective over comm. Units: simulation lengths. Returns OK or kMpi (the same on every rank).
#pragma once

#include <mpi.h>

#include <vector>

#include "core/common/status.h"
#include "core/config/config.h"
#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"

namespace lantern {

inline constexpr int kMaxOcclusionCells = 64;

// Fills (*factor)[i] in (0, 1] for each of this rank's particles (1 for those not drawn).
Status object_occlusion(MPI_Comm comm, const ParticleArrays &particles, const Extent &global,
                        const std::vector<CutPlane> &cuts, double cell, double strength,
                        std::vector<float> *factor);

}  // namespace lantern
