// Screen-door transparency (`opacity` per type): a fragment of opacity alpha is kept
// where the ordered-dither threshold of its pixel is below alpha, and discarded elsewhere, so
// a see-through sphere stays an opaque depth sample wherever it is kept - compositing stays a
// depth minimum and the image stays rank-invariant.
//
// The thresholds are a 4 x 4 Bayer matrix over the image's pixel position (row 0 at the top,
// as Frame stores it): pixel (x, y) has index kBayer4[y mod 4][x mod 4] in 0..15 and threshold
// (index + 0.5) / 16. Opacity travels as 8 bits (alpha8 = round(255 opacity), the sphere
// instance's alpha); the test (2 index + 1) x 255 < 32 x alpha8 is exact in integers and in
// GLSL floats. Every 4 x 4 block of pixels (or of samples, when a scene is super-sampled)
// therefore keeps exactly round-to-nearest(16 opacity) of its 16 fragments: opacity 0.5 keeps 8.
// The GLSL copy lives in gl/sphere_shaders.h (k_bayer); both must stay equal.
#pragma once

#include <cstdint>

namespace lantern {

inline constexpr int kBayer4[16] = {0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5};

// True if a fragment of 8-bit opacity alpha8 at image pixel (x, y), row 0 at the top, is kept.
inline bool screen_door_keeps(int x, int y, uint8_t alpha8) {
  return (2 * kBayer4[(y & 3) * 4 + (x & 3)] + 1) * 255 < 32 * int(alpha8);
}

// An opacity in [0, 1] as the 8 bits the renderers test.
inline uint8_t opacity_alpha8(double opacity) {
  return uint8_t(opacity * 255.0 + 0.5);
}

}  // namespace lantern
