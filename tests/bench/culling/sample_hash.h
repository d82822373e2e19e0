// The uniform random sample the level-of-detail benches compare against: a counter-based hash of
// the particle index (splitmix64's finaliser), so that the sample is the same set on every run
// and rank. Particle i is in the sample of `fraction` when index_hash(i) <= sample_limit(fraction).
#pragma once

#include <cmath>
#include <cstdint>

namespace lantern::bench {

inline uint64_t index_hash(uint64_t i) {
  uint64_t z = i + 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

inline uint64_t sample_limit(double fraction) {
  return fraction >= 1.0 ? UINT64_MAX : uint64_t(std::ldexp(fraction, 64) - 1.0);
}

}  // namespace lantern::bench
