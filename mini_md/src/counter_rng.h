// Counter-based random numbers: a value is a pure function of (seed, key, counter), so an atom's
// random stream depends only on its global id (or lattice index) and the step, never on which
// rank owns it or in which order atoms are visited. That is what makes the initial velocities and
// the Langevin noise independent of the rank count.
#pragma once

#include <cmath>
#include <cstdint>

namespace mini_md {

// SplitMix64 finaliser: a bijective avalanche mix of 64 bits.
inline uint64_t mix64(uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

inline uint64_t hash3(uint64_t seed, uint64_t key, uint64_t counter) {
  return mix64(mix64(mix64(seed) ^ key) ^ counter);
}

// Uniform in the open interval (0, 1): 53 random bits, offset by half an ulp so log() is finite.
inline double uniform01(uint64_t seed, uint64_t key, uint64_t counter) {
  return (static_cast<double>(hash3(seed, key, counter) >> 11) + 0.5) * 0x1.0p-53;
}

// Standard normal by Box-Muller from two independent uniforms.
inline double gaussian(uint64_t seed, uint64_t key, uint64_t counter) {
  const double u1 = uniform01(seed, key, 2 * counter);
  const double u2 = uniform01(seed, key, 2 * counter + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
}

}  // namespace mini_md
