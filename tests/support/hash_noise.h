// Test support: reproducible pseudo-random numbers from an integer (no RNG state to thread
// through, so every rank can recompute any particle's values from its index).
#pragma once

#include <cstdint>

namespace lantern::testing {

// A 32-bit integer hash with good avalanche (lowbias32).
inline uint32_t hash(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

// A hash mapped to [0, 1).
inline double unit(uint32_t h) {
  return double(h & 0xffffff) / double(0x1000000);
}

}  // namespace lantern::testing
