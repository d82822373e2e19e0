// PNG scanline filters (PNG spec 9): the filter types, the filtering of one row of 8-bit pixels
// into a scanline (filter byte + filtered bytes) and the RGBA8 -> RGB copy that RGB files are
// filtered from. png_bands.cpp filters every row of a band with these before compressing it.
//
// Ownership: the functions read and write the caller's buffers during the call only.
// Thread-safety: pure functions without shared state; call them from any thread, concurrently.
// Errors: none; sizes are not checked (deflate_png_band checks the image before it filters).
#pragma once

#include <cstddef>
#include <cstdint>

namespace lantern {

// PNG scanline filter types (PNG spec 9.2). Up, Average and Paeth look at the row above.
enum class PngFilter : uint8_t { kNone = 0, kSub = 1, kUp = 2, kAverage = 3, kPaeth = 4 };

// Writes one scanline: filter byte, then `n` filtered bytes of `cur` (kBpp bytes per pixel),
// `prev` being the same row above (only read by Up / Average / Paeth). Declared here so that
// png_bands.cpp can filter its rows; defined in png_filters.cpp for kBpp 3 (RGB) and 4 (RGBA).
template <int kBpp>
void filter_row(PngFilter filter, const uint8_t *cur, const uint8_t *prev, size_t n, uint8_t *out);
extern template void filter_row<3>(PngFilter, const uint8_t *, const uint8_t *, size_t, uint8_t *);
extern template void filter_row<4>(PngFilter, const uint8_t *, const uint8_t *, size_t, uint8_t *);

// The Sub scanline of the RGB bytes of `width` RGBA8 pixels, straight from the RGBA row: what
// drop_alpha then filter_row<3>(kSub) write, byte for byte, in one pass (AVX2 where the CPU has
// it). `out` receives 1 + 3 * width bytes.
void sub_filter_rgb_of_rgba(const uint8_t *rgba, int width, uint8_t *out);

// Copies the RGB bytes of `width` RGBA8 pixels. Declared here so that png_bands.cpp can turn
// the caller's RGBA8 rows into the RGB rows it filters for 3-channel files.
void drop_alpha(const uint8_t *rgba, int width, uint8_t *rgb);

}  // namespace lantern
