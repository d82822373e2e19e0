#include "core/composite/packed_pixel.h"

namespace lantern {

void pack_pixels(const Frame &frame, size_t first, size_t count, uint64_t *out) {
  const float *depth = frame.depth.data() + first;
  const uint8_t *rgba = frame.rgba.data() + 4 * first;
  for (size_t i = 0; i < count; ++i) out[i] = pack_pixel(depth[i], rgba + 4 * i);
}

void unpack_pixels(const uint64_t *in, size_t first, size_t count, Frame &frame) {
  float *depth = frame.depth.data() + first;
  uint8_t *rgba = frame.rgba.data() + 4 * first;
  for (size_t i = 0; i < count; ++i) unpack_pixel(in[i], depth + i, rgba + 4 * i);
}

void min_merge(const uint64_t *src, size_t count, uint64_t *dst) {
  for (size_t i = 0; i < count; ++i) dst[i] = src[i] < dst[i] ? src[i] : dst[i];
}

}  // namespace lantern
