// What culling hands to drawing: the particles to draw as impostors and those to splat on the
// CPU, each entry (particle index << 32) | (bits of the float radius scale from level of detail).
// Entries are sorted by particle index, so the GPU draws the survivors in the published order,
// exactly as brute force does (ties between equal depths then resolve the same way).
// Ownership: owns its vectors (reused between frames). Thread-safety: none.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>
#include "core/common/page_allocator.h"

namespace lantern {

inline uint64_t draw_entry(uint32_t index, float radius_scale) {
  uint32_t bits;
  std::memcpy(&bits, &radius_scale, sizeof bits);
  return uint64_t(index) << 32 | bits;
}
inline uint32_t entry_index(uint64_t e) {
  return uint32_t(e >> 32);
}
inline float entry_scale(uint64_t e) {
  const auto bits = uint32_t(e);
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

struct DrawList {
  PageVector<uint64_t> spheres;  // GPU impostors
  PageVector<uint64_t> points;   // CPU point path (sub-pixel spheres), when enabled
  // Nothing was culled and nothing changed size: draw every finite particle in published order
  // (`spheres` is then left empty; the caller streams the particles directly).
  bool everything = false;
  void clear() {
    spheres.clear();
    points.clear();
    everything = false;
  }
};

}  // namespace lantern
