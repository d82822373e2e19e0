// One pixel as a single 64-bit key: window depth bits in the high 32, RGBA8 in the low 32.
//
// Why: for non-negative IEEE floats the bit pattern orders like the value, so the integer minimum
// of two keys is "the nearer pixel", and on equal depth "the smaller color (R, then G, B, A)".
// That one rule is commutative and associative, so any reduction order, any rank count and any
// algorithm (MPI_MIN, binary swap, serial) yields bit-identical pixels.
//
// The color is packed as R<<24 | G<<16 | B<<8 | A (byte order fixed below), so the key and the
// tie-break are the same on little- and big-endian machines.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "core/view/frame.h"

namespace lantern {

// Depth as compositing sees it: negative values and -0 become +0 (their sign bit would otherwise
// sort them behind the background), NaN becomes background.
inline float canonical_depth(float depth) {
  if (depth > 0.0f) return depth;
  return depth == depth ? 0.0f : kBackgroundDepth;
}

// The color word R<<24 | G<<16 | B<<8 | A from 4 bytes in memory order, and back. One 32-bit
// load plus a byte swap on little-endian machines: a byte-by-byte version is several times
// slower in the pack/unpack loops.
inline uint32_t color_word(const uint8_t *rgba) {
  uint32_t w;
  std::memcpy(&w, rgba, sizeof w);
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  w = __builtin_bswap32(w);
#endif
  return w;
}
inline void store_color_word(uint32_t w, uint8_t *rgba) {
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  w = __builtin_bswap32(w);
#endif
  std::memcpy(rgba, &w, sizeof w);
}

inline uint64_t pack_pixel(float depth, const uint8_t *rgba) {
  const float d = canonical_depth(depth);
  uint32_t bits;
  std::memcpy(&bits, &d, sizeof bits);
  return uint64_t(bits) << 32 | color_word(rgba);
}

inline void unpack_pixel(uint64_t key, float *depth, uint8_t *rgba) {
  const uint32_t bits = uint32_t(key >> 32);
  std::memcpy(depth, &bits, sizeof bits);
  store_color_word(uint32_t(key), rgba);
}

// Packs pixels [first, first + count) of frame into out[0, count).
void pack_pixels(const Frame &frame, size_t first, size_t count, uint64_t *out);

// Unpacks in[0, count) into pixels [first, first + count) of frame.
void unpack_pixels(const uint64_t *in, size_t first, size_t count, Frame &frame);

// Merges count incoming pixels into (depth, rgba) by the rule above, in place. Every pixel is
// rewritten from the winning key, so its depth comes out canonical exactly as after an MPI_MIN
// of packed keys: the hand-written and the MPI methods stay bit-identical.
void merge_pixels(const float *in_depth, const uint8_t *in_rgba, size_t count, float *depth,
                  uint8_t *rgba);

}  // namespace lantern
