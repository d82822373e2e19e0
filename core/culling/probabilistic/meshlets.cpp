#include "core/culling/probabilistic/meshlets.h"

#include <algorithm>

#include "core/bricks/morton.h"
#include "core/particles/typed_access.h"

namespace lantern {

void MeshletSet::build(const ParticleArrays &particles, const BrickSet &bricks) {
  generation = bricks.generation;
  slots.resize(bricks.order.size());
  meshlets.clear();
  first_of_brick.assign(bricks.bricks.size() + 1, 0);
  std::vector<std::pair<uint64_t, uint32_t>> keyed;
  visit_positions(particles, [&](const auto &pos) {
    for (size_t b = 0; b < bricks.bricks.size(); ++b) {
      const Brick &brick = bricks.bricks[b];
      first_of_brick[b] = uint32_t(meshlets.size());
      const glm::dvec3 ext = glm::max(brick.hi - brick.lo, glm::dvec3(1e-300));
      keyed.clear();
      for (uint32_t k = 0; k < brick.count; ++k) {
        const glm::dvec3 f = (pos.get(bricks.order[brick.first + k]) - brick.lo) / ext * 1023.0;
        const auto q = [](double v) { return uint32_t(std::clamp(v, 0.0, 1023.0)); };
        keyed.push_back({morton_encode(q(f.x), q(f.y), q(f.z)), k});
      }
      std::sort(keyed.begin(), keyed.end());
      for (uint32_t k = 0; k < brick.count; ++k) slots[brick.first + k] = keyed[k].second;
      for (uint32_t k = 0; k < brick.count; k += kMeshletSize) {
        Meshlet m;
        m.first = brick.first + k;
        m.count = std::min(kMeshletSize, brick.count - k);
        m.lo = glm::dvec3(1e300), m.hi = glm::dvec3(-1e300);
        for (uint32_t j = 0; j < m.count; ++j) {
          const uint32_t i = bricks.order[brick.first + slots[m.first + j]];
          const glm::dvec3 p = pos.get(i);
          m.lo = glm::min(m.lo, p), m.hi = glm::max(m.hi, p);
          if (particles.has_radius()) m.max_radius = std::max(m.max_radius, particles.radius(i));
        }
        meshlets.push_back(m);
      }
    }
  });
  first_of_brick.back() = uint32_t(meshlets.size());
}

}  // namespace lantern
