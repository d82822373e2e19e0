#include "core/output/png/png_filters.h"

#include <cstdlib>
#include <cstring>

namespace lantern {

namespace {

uint8_t paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return static_cast<uint8_t>(a);
  return static_cast<uint8_t>(pb <= pc ? b : c);
}

}  // namespace

template <int kBpp>
void filter_row(PngFilter filter, const uint8_t *cur, const uint8_t *prev, size_t n, uint8_t *out) {
  *out++ = static_cast<uint8_t>(filter);
  switch (filter) {
    case PngFilter::kNone:
      std::memcpy(out, cur, n);
      break;
    case PngFilter::kSub:
      for (size_t i = 0; i < kBpp; ++i) out[i] = cur[i];
      for (size_t i = kBpp; i < n; ++i) out[i] = static_cast<uint8_t>(cur[i] - cur[i - kBpp]);
      break;
    case PngFilter::kUp:
      for (size_t i = 0; i < n; ++i) out[i] = static_cast<uint8_t>(cur[i] - prev[i]);
      break;
    case PngFilter::kAverage:
      for (size_t i = 0; i < kBpp; ++i) out[i] = static_cast<uint8_t>(cur[i] - (prev[i] >> 1));
      for (size_t i = kBpp; i < n; ++i)
        out[i] = static_cast<uint8_t>(cur[i] - ((cur[i - kBpp] + prev[i]) >> 1));
      break;
    case PngFilter::kPaeth:
      for (size_t i = 0; i < kBpp; ++i) out[i] = static_cast<uint8_t>(cur[i] - prev[i]);
      for (size_t i = kBpp; i < n; ++i)
        out[i] = static_cast<uint8_t>(cur[i] - paeth(cur[i - kBpp], prev[i], prev[i - kBpp]));
      break;
  }
}

void drop_alpha(const uint8_t *rgba, int width, uint8_t *rgb) {
  for (int x = 0; x < width; ++x, rgba += 4, rgb += 3) {
    rgb[0] = rgba[0];
    rgb[1] = rgba[1];
    rgb[2] = rgba[2];
  }
}

// The instantiations png_filters.h declares: RGB and RGBA rows.
template void filter_row<3>(PngFilter, const uint8_t *, const uint8_t *, size_t, uint8_t *);
template void filter_row<4>(PngFilter, const uint8_t *, const uint8_t *, size_t, uint8_t *);

}  // namespace lantern
