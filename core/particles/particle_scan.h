// The per-frame pass over this rank's particles that every scene needs first: bounds, the
// largest radius, the scalar range and the count of particles skipped for NaN/inf coordinates.
#pragma once

#include <cmath>

#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"

namespace lantern {

// Scans the rank's particles. `radius` is the scene-wide radius used when `per_particle_radius`
// is false (or no radius array was published). Particles outside the published group (mask) are
// left out entirely: they count neither as finite nor as non-finite. `threads`: the common case
// (no radius array, no scalar) runs in that many parts, merged in part order: the same bits.
Extent scan_particles(const ParticleArrays &particles, bool per_particle_radius, double radius,
                      int threads = 1);

// True when particle i has finite coordinates (the same test scan_particles counts with).
inline bool finite_position(const glm::dvec3 &p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

}  // namespace lantern
