// Ibrahim et al.'s two-level object hierarchy (§3.1): nodes are the bricks (core/bricks/), and each
// brick's particles are cut into meshlets of kMeshletSize spatially consecutive particles. A
// brick's own order is its level layout (a uniform sample at every prefix, not spatially
// compact), so each brick's particles are first put back in z-order of their positions inside
// the brick; meshlet m of a brick then holds the next kMeshletSize of them.
//
// A meshlet refers to particles by their slot k in the brick's order (BrickSet::order[first + k]),
// so level of detail's kept prefix (k < keep) applies to it directly.
// Ownership: owns its arrays; valid for the BrickSet of the generation it was built for.
// Thread-safety: immutable after build.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/bricks/brick_set.h"
#include "core/particles/particle_arrays.h"

namespace lantern {

inline constexpr uint32_t kMeshletSize = 16;

struct Meshlet {
  uint32_t first = 0;  // offset into MeshletSet::slots
  uint32_t count = 0;
  glm::dvec3 lo{0.0}, hi{0.0};  // bounds of the centres
  double max_radius = 0.0;      // largest published radius (0 without a radius array)
};

struct MeshletSet {
  uint64_t generation = 0;               // the BrickSet::generation built from (0: none)
  std::vector<uint32_t> slots;           // per meshlet, its particles' slots in their brick
  std::vector<Meshlet> meshlets;         // brick after brick
  std::vector<uint32_t> first_of_brick;  // bricks + 1 entries: meshlets of brick b

  void build(const ParticleArrays &particles, const BrickSet &bricks);
};

}  // namespace lantern
