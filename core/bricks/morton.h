// Morton (z-order) keys: 21 bits per axis interleaved into a 63-bit key, x the most significant
// bit of each triple. Sorting by key orders particles along the z-order curve, so every run of
// keys sharing a 3l-bit prefix is one cell of an octree of depth l (Rizzi et al. 2015, §3.5).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

#include <glm/vec3.hpp>

namespace lantern {

inline constexpr int kMortonBitsPerAxis = 21;
inline constexpr uint32_t kMortonAxisMax = (1u << kMortonBitsPerAxis) - 1;

// Spreads the low 21 bits of v so that bit k lands on bit 3k.
inline uint64_t morton_spread3(uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

// Inverse of morton_spread3: gathers bits 0, 3, 6, ... into the low 21 bits.
inline uint32_t morton_compact3(uint64_t v) {
  v &= 0x1249249249249249ull;
  v = (v ^ (v >> 2)) & 0x10c30c30c30c30c3ull;
  v = (v ^ (v >> 4)) & 0x100f00f00f00f00full;
  v = (v ^ (v >> 8)) & 0x1f0000ff0000ffull;
  v = (v ^ (v >> 16)) & 0x1f00000000ffffull;
  v = (v ^ (v >> 32)) & 0x1fffffull;
  return uint32_t(v);
}

inline uint64_t morton_encode(uint32_t x, uint32_t y, uint32_t z) {
  return morton_spread3(x) << 2 | morton_spread3(y) << 1 | morton_spread3(z);
}

// The key's top 32 bits (morton_encode(x, y, z) >> 31), which order particles down to cells of
// 1/2^10.67 of the box (the brick build's sort key): bits 10..20 of x and y and 11..20 of z,
// spread by a table of the 2048 11-bit values instead of five shift-and-mask steps per axis.
namespace morton_detail {
constexpr std::array<uint32_t, 2048> spread11_table() {
  std::array<uint32_t, 2048> t{};
  for (uint32_t v = 0; v < 2048; ++v)
    for (int b = 0; b < 11; ++b) t[v] |= ((v >> b) & 1u) << (3 * b);
  return t;
}
inline constexpr std::array<uint32_t, 2048> kSpread11 = spread11_table();
}  // namespace morton_detail

inline uint32_t morton_prefix(uint32_t x, uint32_t y, uint32_t z) {
  const auto &t = morton_detail::kSpread11;
  return t[x >> 10] << 1 | t[y >> 10] | t[z >> 10] >> 1;
}

// Maps positions in a box to integer lattice coordinates. The scale is the same on every axis so
// that octree cells are cubes (compact bricks), sized by the box's longest side.
struct MortonQuantiser {
  glm::dvec3 lo{0.0};
  double scale = 1.0;  // lattice steps per length unit

  static MortonQuantiser for_bounds(const glm::dvec3 &lo, const glm::dvec3 &hi) {
    const double side = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    MortonQuantiser q;
    q.lo = lo;
    q.scale = side > 0.0 ? double(kMortonAxisMax) / side : 0.0;
    return q;
  }
  uint32_t axis(double v, double origin) const {
    const double s = (v - origin) * scale;  // in [0, kMortonAxisMax] for points in the box
    return s <= 0.0 ? 0u : s >= double(kMortonAxisMax) ? kMortonAxisMax : uint32_t(s);
  }
  uint64_t key(const glm::dvec3 &p) const {
    return morton_encode(axis(p.x, lo.x), axis(p.y, lo.y), axis(p.z, lo.z));
  }
  uint32_t prefix(const glm::dvec3 &p) const {  // key(p) >> 31
    return morton_prefix(axis(p.x, lo.x), axis(p.y, lo.y), axis(p.z, lo.z));
  }
};

}  // namespace lantern
