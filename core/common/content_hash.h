// A 64-bit FNV-1a hash of a byte string: tells whether two configuration texts (on two ranks, or
// a file before and after an edit) are the same without sending or keeping the texts. Not
// cryptographic. Thread-safety: pure function.
#pragma once

#include <cstdint>
#include <string_view>

namespace lantern {

inline uint64_t content_hash(std::string_view bytes) {
  uint64_t h = 1469598103934665603ull;  // FNV-1a offset basis
  for (const char c : bytes) {
    h ^= uint64_t(static_cast<unsigned char>(c));
    h *= 1099511628211ull;  // FNV prime
  }
  return h;
}

}  // namespace lantern
