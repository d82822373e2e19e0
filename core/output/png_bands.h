// PNG files compressed in horizontal bands, so that the bands can be compressed in parallel on
// different threads or MPI ranks and joined by the root without recompressing anything.
//
// Why this exists: libpng (and OpenImageIO on top of it) compresses a whole image as one zlib
// stream on one thread, and at zlib level 1 with libpng's adaptive filter choice a 1024x1024
// RGBA frame costs ~58 ms. Here each band becomes a raw deflate piece that ends on a byte boundary
// (Z_SYNC_FLUSH; the last band ends with Z_FINISH), so pieces of consecutive bands concatenate
// into one valid deflate stream (the pigz technique). The zlib checksum of the whole stream is
// combined from the bands' adler32 values with adler32_combine. zlib does all the compression;
// this file only filters scanlines and lays out the PNG container (signature, IHDR, IDAT, IEND).
//
// Filtering: every scanline of a band may only refer to rows the decoder will have decoded
// before it, which is always true inside the band. The first row of a band refers to nothing
// above it unless the caller passes the previous image row (`previous_row`), so bands never
// depend on another band's bytes, only (optionally) on one row of pixels.
//
// Default filter and strategy (PngBandOptions): Sub + Z_RLE at the caller's level (1 in situ),
// the fastest pair in lantern-bench-png's filter x strategy table on 1024x1024 sphere renders:
// deflate takes ~90% of the time (filtering + adler32 ~2 ms), and Z_RLE's cost barely depends on
// the content, while LZ77 (Z_DEFAULT_STRATEGY) costs 1.1-2x as much. Sub needs no row above, so
// bands need no halo row. Files vs OpenImageIO's level 1 (RGBA): ~1.06x with a colour per atom,
// 1.27x on a real one-colour fcc render. One-colour crystals repeat the same sphere sprite, which
// LZ77 exploits: {kNone, kDefault} gives 0.71x of OIIO's size there at ~1.1-1.5x the time of the
// default, and ~2x the time with a colour per atom. Up / Average + Z_RLE are as fast and ~2%
// smaller but want `previous_row`; Paeth costs ~1.5x; Z_HUFFMAN_ONLY is slower than Z_RLE (no
// runs over the background) and larger.
//
// Ownership: the functions read the caller's pixels during the call only and return buffers
// the caller owns. Thread-safety: pure functions without shared state; call them from any
// thread, concurrently. Errors: deflate_png_band throws std::invalid_argument for bad arguments
// (and std::bad_alloc / std::runtime_error if zlib runs out of memory); assemble_png and
// encode_png never throw and report errors as messages.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace lantern {

// PNG scanline filter types (PNG spec 9.2). Up, Average and Paeth look at the row above.
enum class PngFilter : uint8_t { kNone = 0, kSub = 1, kUp = 2, kAverage = 3, kPaeth = 4 };

// zlib strategies (deflateInit2): Z_DEFAULT_STRATEGY, Z_FILTERED, Z_RLE, Z_HUFFMAN_ONLY.
enum class PngStrategy { kDefault, kFiltered, kRle, kHuffmanOnly };

struct PngBandOptions {
  // The filter of every row. A band's first row without `previous_row` uses Sub instead of
  // Up / Average / Paeth (None stays None), so it never refers to a row the band does not have.
  PngFilter filter = PngFilter::kSub;
  PngStrategy strategy = PngStrategy::kRle;
};

// One band's compressed piece and what the root needs to join it to the others.
struct PngBand {
  std::vector<uint8_t> bytes;  // raw deflate data (no zlib header or trailer), owned
  uint32_t adler = 1;          // adler32 of the band's uncompressed filtered scanlines
  uint64_t raw_len = 0;        // their length: rows * (1 + width * channels_out)
  int rows = 0;                // scanlines in the band
  bool last = false;           // ends the deflate stream (Z_FINISH)
};

// Compresses `rows` rows of RGBA8 pixels (`rgba`: row stride width * 4 bytes, top row first)
// as PNG scanlines (filter byte + filtered bytes of RGB when channels_out == 3, dropping alpha,
// or of RGBA when 4). The piece ends with Z_SYNC_FLUSH, or with Z_FINISH when `last_band`, so
// the pieces of consecutive bands, in order, form one deflate stream. `level` is the zlib
// level 0..9. `previous_row`: the RGBA8 row just above the band (width * 4 bytes) or nullptr;
// only Up / Average / Paeth use it. rows == 0 is allowed (an empty piece).
// Throws std::invalid_argument if width < 1, rows < 0, channels_out is not 3 or 4, level is
// outside 0..9 or rgba is null with rows > 0.
PngBand deflate_png_band(const uint8_t *rgba, int width, int rows, int channels_out, bool last_band,
                         int level, const uint8_t *previous_row = nullptr,
                         const PngBandOptions &options = {});

// Lays out a PNG file from the bands of one image, top band first: signature, IHDR (8-bit,
// colour type 2 for channels_out == 3 or 6 for 4, no interlace), IDAT chunks of at most
// 1 MiB holding the zlib header, the concatenated pieces and the combined adler32, then IEND.
// Replaces *file. Returns false with a message in *error (if not null) when the bands do not
// describe a width x height image (row count, raw length, only the last band finishing).
bool assemble_png(const std::vector<PngBand> &bands, int width, int height, int channels_out,
                  std::vector<uint8_t> *file, std::string *error);

// The whole image in one call: splits `rgba` (width x height RGBA8, top row first) into
// min(threads, height) bands of near-equal row counts, compresses them on that many threads
// (the calling thread included; threads <= 1 runs sequentially) and assembles the file. Each
// band gets its previous row, so every filter is usable. Returns the PNG file's bytes, or an
// empty vector with a message in *error (if not null).
std::vector<uint8_t> encode_png(const uint8_t *rgba, int width, int height, int channels_out,
                                int level, int threads, std::string *error = nullptr,
                                const PngBandOptions &options = {});

}  // namespace lantern
