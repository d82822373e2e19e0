// How one scene sizes its spheres, resolved once per scene and step and handed to every stage
// that needs it (camera fit, brick selection, culling, instances, splats, renderer choice).
//
// Plain value type. Units: the simulation's length unit.
#pragma once

#include <algorithm>

#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"

namespace lantern {

struct RadiusRule {
  // The scene asks for the published radii (`radius: per_particle`), whatever this rank has.
  bool wanted = false;
  // This rank reads its radius array: wanted, and the array was published. (A rank with no
  // particles may have published none; one with particles but no array is an error the
  // pipeline reports before drawing.)
  bool per_particle = false;
  double radius = 0.5;  // the scene's radius, for every particle when not per_particle

  // The rule of a scene whose radius is `radius` for every particle, or the published radii when
  // `per_particle` (`radius: per_particle`), for this rank's `particles`.
  static RadiusRule of(bool per_particle, double radius, const ParticleArrays &particles) {
    RadiusRule r;
    r.wanted = per_particle;
    r.per_particle = r.wanted && particles.has_radius();
    r.radius = radius;
    return r;
  }

  // The largest radius any particle on any rank is drawn with (`global`: reduced over ranks), the
  // same on every rank.
  double max_radius(const Extent &global) const {
    return wanted ? std::max(global.max_radius, 0.0) : radius;
  }
};

}  // namespace lantern
