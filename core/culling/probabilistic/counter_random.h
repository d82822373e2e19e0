// Counter-based random numbers for probabilistic culling: every draw is a pure function of its
// key (step, pixel, sample, iteration, and a stream tag), so a rerun - on any thread, in any
// order - draws the same numbers and writes the same bytes. SplitMix64's finaliser (Steele, Lea
// and Flood 2014) mixes each key word in turn; it passes BigCrush as a counter-mode generator,
// which is more than a coin for sample acceptance needs. No std::rand, no time seeds.
// Thread-safety: pure functions.
#pragma once

#include <cstdint>

namespace lantern {

// The streams drawn from one key, so that two uses of the same (step, pixel, ...) never share a
// number.
enum class RandomStream : uint64_t { kJitterX = 1, kJitterY, kAcceptance, kShuffle };

inline uint64_t splitmix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// A 64-bit hash of the key (step, pixel or node, sample, iteration, stream).
inline uint64_t counter_hash(uint64_t step, uint64_t where, uint64_t sample, uint64_t iteration,
                             RandomStream stream) {
  uint64_t h = splitmix64(step ^ 0x6c616e7465726e31ull);  // "lantern1": a fixed seed
  h = splitmix64(h ^ where);
  h = splitmix64(h ^ sample);
  h = splitmix64(h ^ iteration);
  return splitmix64(h ^ uint64_t(stream));
}

// Uniform in [0, 1) from the top 53 bits of a hash.
inline double unit_interval(uint64_t h) {
  return double(h >> 11) * (1.0 / 9007199254740992.0);
}

}  // namespace lantern
