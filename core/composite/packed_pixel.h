// One pixel as a single 64-bit key: window depth bits in the high 32, RGBA8 in the low 32.
//
// Why: for non-negative IEEE floats the bit pattern orders like the value, so the integer minimum
// of two keys is "the nearer pixel", and on equal depth "the smaller colour (R, then G, B, A)".
// That one rule is commutative and associative, so any reduction order, any rank count and any
// algorithm (MPI_MIN, binary swap, serial) yields bit-identical pixels.
//
// The colour is packed as R<<24 | G<<16 | B<<8 | A by shifts, never by memcpy, so the key and the
// tie-break are the same on little- and big-endian machines.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "core/render/frame.h"

namespace lantern {

// Depth as compositing sees it: negative values and -0 become +0 (their sign bit would otherwise
// sort them behind the background), NaN becomes background.
inline float canonical_depth(float depth) {
  if (depth > 0.0f) return depth;
  return depth == depth ? 0.0f : kBackgroundDepth;
}

inline uint64_t pack_pixel(float depth, const uint8_t *rgba) {
  const float d = canonical_depth(depth);
  uint32_t bits;
  std::memcpy(&bits, &d, sizeof bits);
  const uint32_t colour = uint32_t(rgba[0]) << 24 | uint32_t(rgba[1]) << 16 |
                          uint32_t(rgba[2]) << 8 | uint32_t(rgba[3]);
  return uint64_t(bits) << 32 | colour;
}

inline void unpack_pixel(uint64_t key, float *depth, uint8_t *rgba) {
  const uint32_t bits = uint32_t(key >> 32);
  std::memcpy(depth, &bits, sizeof bits);
  rgba[0] = uint8_t(key >> 24);
  rgba[1] = uint8_t(key >> 16);
  rgba[2] = uint8_t(key >> 8);
  rgba[3] = uint8_t(key);
}

// Packs pixels [first, first + count) of frame into out[0, count).
void pack_pixels(const Frame &frame, size_t first, size_t count, uint64_t *out);

// Unpacks in[0, count) into pixels [first, first + count) of frame.
void unpack_pixels(const uint64_t *in, size_t first, size_t count, Frame &frame);

// dst[i] = min(dst[i], src[i]): the merge rule above, for the hand-written algorithms.
void min_merge(const uint64_t *src, size_t count, uint64_t *dst);

}  // namespace lantern
