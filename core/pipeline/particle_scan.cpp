#include "core/pipeline/particle_scan.h"

namespace lantern {

Extent scan_particles(const ParticleArrays &particles, bool per_particle_radius, double radius) {
  Extent e;
  const bool use_radius_array = per_particle_radius && particles.has_radius();
  const bool has_scalar = particles.has_scalar();
  for (int64_t i = 0; i < particles.count(); ++i) {
    const glm::dvec3 p = particles.position(i);
    const double r = use_radius_array ? particles.radius(i) : radius;
    if (e.add_particle(p.x, p.y, p.z, r) && has_scalar) e.add_scalar(particles.scalar(i));
  }
  return e;
}

}  // namespace lantern
