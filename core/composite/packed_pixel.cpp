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

void merge_pixels(const float *in_depth, const uint8_t *in_rgba, size_t count, float *depth,
                  uint8_t *rgba) {
  for (size_t i = 0; i < count; ++i) {
    const uint64_t in = pack_pixel(in_depth[i], in_rgba + 4 * i);
    const uint64_t own = pack_pixel(depth[i], rgba + 4 * i);
    unpack_pixel(in < own ? in : own, depth + i, rgba + 4 * i);
  }
}

}  // namespace lantern
