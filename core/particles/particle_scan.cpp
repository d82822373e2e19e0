#include "core/particles/particle_scan.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/common/rank_threads.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

// The sign of a bound that came out exactly zero: the first kept, finite particle in [begin, end)
// whose coordinate c is zero, since a one-pass min (or max) keeps the first of equal values and
// -0 equals +0. Stops there, usually at once.
template <typename Positions, typename Keep>
double first_zero(const Positions &pos, const Keep &keep, int64_t begin, int64_t end, int c) {
  for (int64_t i = begin; i < end; ++i) {
    if (!keep.get(i)) continue;
    const glm::dvec3 p = pos.get(i);
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && p[c] == 0.0) return p[c];
  }
  return 0.0;
}

// The common case (one radius, no coloring scalar): the same result as Extent::add_particle for
// every particle in order, bit for bit. Four lanes take every fourth particle so that the min and
// max chains run side by side; lanes give the same values as one pass, and where a bound is zero
// (-0 or +0, equal but two encodings) first_zero finds the one a single pass keeps.
// Particles outside the group (`keep`) are not counted at all, neither finite nor non-finite.
template <typename Positions, typename Keep>
Extent scan_positions(const Positions &pos, const Keep &keep, int64_t begin, int64_t end,
                      double radius) {
  constexpr int kLanes = 4;
  double lo[kLanes][3], hi[kLanes][3];
  for (int l = 0; l < kLanes; ++l)
    for (int c = 0; c < 3; ++c) lo[l][c] = Extent::kInf, hi[l][c] = -Extent::kInf;
  int64_t finite = 0, left_out = 0;
  const auto add = [&](int l, int64_t i) {
    if (!keep.get(i)) {
      ++left_out;
      return;
    }
    const glm::dvec3 p = pos.get(i);
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) return;
    lo[l][0] = std::min(lo[l][0], p.x), lo[l][1] = std::min(lo[l][1], p.y);
    lo[l][2] = std::min(lo[l][2], p.z);
    hi[l][0] = std::max(hi[l][0], p.x), hi[l][1] = std::max(hi[l][1], p.y);
    hi[l][2] = std::max(hi[l][2], p.z);
    ++finite;
  };
  int64_t i = begin;
  for (; i + kLanes <= end; i += kLanes)
    for (int l = 0; l < kLanes; ++l) add(l, i + l);
  for (; i < end; ++i) add(0, i);
  Extent e;
  for (int c = 0; c < 3; ++c) {
    double a = lo[0][c], b = hi[0][c];
    for (int l = 1; l < kLanes; ++l) a = std::min(a, lo[l][c]), b = std::max(b, hi[l][c]);
    if (a == 0.0) a = first_zero(pos, keep, begin, end, c);
    if (b == 0.0) b = first_zero(pos, keep, begin, end, c);
    e.lo[size_t(c)] = a, e.hi[size_t(c)] = b;
  }
  e.finite_count = finite;
  e.nonfinite_count = end - begin - left_out - finite;
  if (finite > 0 && std::isfinite(radius)) e.max_radius = radius;
  return e;
}

// Later parts into the first: min and max keep the first of equal values (std::min/max), so
// merging in part order gives one pass's bits, -0 and +0 included.
void merge_part(const Extent &later, Extent *e) {
  for (size_t k = 0; k < 3; ++k) {
    e->lo[k] = std::min(e->lo[k], later.lo[k]);
    e->hi[k] = std::max(e->hi[k], later.hi[k]);
  }
  e->finite_count += later.finite_count;
  e->nonfinite_count += later.nonfinite_count;
  e->max_radius = std::max(e->max_radius, later.max_radius);
}

}  // namespace

Extent scan_particles(const ParticleArrays &particles, bool per_particle_radius, double radius,
                      int threads) {
  const bool use_radius_array = per_particle_radius && particles.has_radius();
  const bool has_scalar = particles.has_scalar();
  if (!use_radius_array && !has_scalar)
    return visit_positions(particles, [&](const auto &pos) {
      return visit_kept(particles, [&](const auto &keep) {
        const int parts = parts_for(threads, particles.count(), int64_t(1) << 16);
        std::vector<Extent> part(static_cast<size_t>(parts));
        run_in_parts(parts, particles.count(), [&](int p, int64_t b, int64_t e) {
          part[size_t(p)] = scan_positions(pos, keep, b, e, radius);
        });
        for (size_t p = 1; p < part.size(); ++p) merge_part(part[p], &part[0]);
        return part[0];
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
