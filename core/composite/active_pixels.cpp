#include "core/composite/active_pixels.h"

#include <cstring>

#include "core/composite/packed_pixel.h"

namespace lantern {
namespace {

constexpr int kBlock = 16;  // pixels compared at once against the running maximum

uint32_t depth_bits(const float *depth, size_t i) {
  uint32_t b;
  std::memcpy(&b, depth + i, sizeof b);
  return b;
}

uint32_t rgba_word(const uint8_t *rgba, size_t i) {
  uint32_t w;
  std::memcpy(&w, rgba + 4 * i, sizeof w);
  return w;
}

// True if pixels [i, i + n) all hold exactly these depth bits and colour word (no unpacking: a
// pixel whose raw bits equal a canonical key's is that key).
bool all_equal(const float *depth, const uint8_t *rgba, size_t i, int n, uint32_t d, uint32_t c) {
  uint32_t differ = 0;
  for (int t = 0; t < n; ++t)
    differ |= (depth_bits(depth, i + size_t(t)) ^ d) | (rgba_word(rgba, i + size_t(t)) ^ c);
  return differ == 0;
}

// The pixel's key after writing its depth back in canonical form.
uint64_t canonical_key(float *depth, const uint8_t *rgba, size_t i) {
  const float canonical = canonical_depth(depth[i]);
  if (depth_bits(depth, i) != depth_bits(&canonical, 0)) depth[i] = canonical;
  return pack_pixel(canonical, rgba + 4 * i);
}

}  // namespace

EmptyPixel empty_pixel(uint64_t key) {
  EmptyPixel e;
  e.key = key;
  e.depth_bits = uint32_t(key >> 32);
  uint8_t rgba[4];
  store_color_word(uint32_t(key), rgba);
  std::memcpy(&e.rgba_word, rgba, sizeof e.rgba_word);
  return e;
}

ActiveScan scan_active_pixels(Frame &frame) {
  ActiveScan scan;
  const size_t pixels = frame.pixel_count();
  if (pixels == 0) return scan;
  float *depth = frame.depth.data();
  const uint8_t *rgba = frame.rgba.data();
  const int width = frame.width;
  uint64_t max_key = canonical_key(depth, rgba, 0);
  EmptyPixel m = empty_pixel(max_key);
  size_t active = 0;
  for (int y = 0; y < frame.height; ++y) {
    const size_t row = size_t(y) * size_t(width);
    int row_x0 = width, row_x1 = 0;  // active columns [row_x0, row_x1) of this row
    for (int x = y == 0 ? 1 : 0; x < width;) {
      const int n = std::min(kBlock, width - x);
      if (all_equal(depth, rgba, row + size_t(x), n, m.depth_bits, m.rgba_word)) {
        x += n;
        continue;
      }
      for (const int end = x + n; x < end; ++x) {
        const uint64_t key = canonical_key(depth, rgba, row + size_t(x));
        if (key < max_key) {
          ++active;
          row_x0 = std::min(row_x0, x);
          row_x1 = x + 1;
        } else if (key > max_key) {
          // A new maximum: every pixel before this one is below it, so active.
          active = row + size_t(x);
          if (y > 0) scan.rect.add(0, 0, width, y);
          if (x > 0) row_x0 = 0, row_x1 = std::max(row_x1, x);
          max_key = key;
          m = empty_pixel(max_key);
        }
      }
    }
    scan.rect.add(row_x0, y, row_x1, y + 1);
  }
  scan.max_key = max_key;
  scan.active = active;
  return scan;
}

}  // namespace lantern
