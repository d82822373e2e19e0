#include "core/particles/particle_scan.h"

#include <algorithm>
#include <cmath>

#include "core/particles/typed_access.h"

namespace lantern {
namespace {

// The common case (one radius, no coloring scalar) in a loop the compiler keeps in registers:
// the same result as Extent::add_particle for every particle.
// Particles outside the group (`keep`) are not counted at all, neither finite nor non-finite.
template <typename Positions, typename Keep>
Extent scan_positions(const Positions &pos, const Keep &keep, int64_t count, double radius) {
  Extent e;
  double lo[3] = {Extent::kInf, Extent::kInf, Extent::kInf};
  double hi[3] = {-Extent::kInf, -Extent::kInf, -Extent::kInf};
  int64_t finite = 0, left_out = 0;
  for (int64_t i = 0; i < count; ++i) {
    if (!keep.get(i)) {
      ++left_out;
      continue;
    }
    const glm::dvec3 p = pos.get(i);
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) continue;
    lo[0] = std::min(lo[0], p.x), lo[1] = std::min(lo[1], p.y), lo[2] = std::min(lo[2], p.z);
    hi[0] = std::max(hi[0], p.x), hi[1] = std::max(hi[1], p.y), hi[2] = std::max(hi[2], p.z);
    ++finite;
  }
  for (int k = 0; k < 3; ++k) e.lo[size_t(k)] = lo[k], e.hi[size_t(k)] = hi[k];
  e.finite_count = finite;
  e.nonfinite_count = count - left_out - finite;
  if (finite > 0 && std::isfinite(radius)) e.max_radius = radius;
  return e;
}

}  // namespace

Extent scan_particles(const ParticleArrays &particles, bool per_particle_radius, double radius) {
  const bool use_radius_array = per_particle_radius && particles.has_radius();
  const bool has_scalar = particles.has_scalar();
  if (!use_radius_array && !has_scalar)
    return visit_positions(particles, [&](const auto &pos) {
      return visit_kept(particles, [&](const auto &keep) {
        return scan_positions(pos, keep, particles.count(), radius);
      });
    });
  Extent e;
  for (int64_t i = 0; i < particles.count(); ++i) {
    if (!particles.kept(i)) continue;
    const glm::dvec3 p = particles.position(i);
    const double r = use_radius_array ? particles.radius(i) : radius;
    if (e.add_particle(p.x, p.y, p.z, r) && has_scalar) e.add_scalar(particles.scalar(i));
  }
  return e;
}

}  // namespace lantern
