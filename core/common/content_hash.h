// 64-bit FNV-1a hashes: whether two configuration texts (on two ranks, or a file before and after
// an edit) are the same without sending or keeping the texts, and whether a host's particle
// arrays were rewritten in place (core/bricks/brick_cache.h), without keeping a copy. Not
// cryptographic. Thread-safety: pure functions.
#pragma once

#include <cstdint>
#include <string_view>

namespace lantern {

inline constexpr uint64_t kContentHashBasis = 1469598103934665603ull;  // FNV-1a offset basis

// Folds one value into the hash `h` (FNV-1a's step: xor, then multiply by the FNV prime). For
// bytes that is FNV-1a itself; whole 64-bit words fold eight bytes in one step (a cheaper hash of
// the same kind, for fingerprints compared only with each other).
inline uint64_t content_hash_step(uint64_t h, uint64_t value) {
  return (h ^ value) * 1099511628211ull;  // FNV prime
}

// FNV-1a of a byte string.
inline uint64_t content_hash(std::string_view bytes) {
  uint64_t h = kContentHashBasis;
  for (const char c : bytes) h = content_hash_step(h, uint64_t(static_cast<unsigned char>(c)));
  return h;
}

}  // namespace lantern
