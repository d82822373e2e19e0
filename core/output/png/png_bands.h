// PNG files compressed in horizontal bands, so that the bands can be compressed in parallel on
// different threads or MPI ranks and joined by the root without recompressing anything.
//
// Why this exists: libpng (and OpenImageIO on top of it) compresses a whole image as one zlib
// stream on one thread, and at zlib level 1 with libpng's adaptive filter choice a 1024x1024
// RGBA frame costs ~58 ms. Here each band becomes a raw deflate piece that ends on a byte boundary
// (an empty stored block, as Z_SYNC_FLUSH; the last band ends the stream), so pieces of
// consecutive bands concatenate into one valid deflate stream (the pigz technique). The zlib
// checksum of the whole stream is combined from the bands' adler32 values with adler32_combine.
// This file cuts an image into bands and compresses them: it filters each band's scanlines
// (png_filters.h) and hands them to the encoder; png_container.h lays out the file from the
// pieces. It includes both headers, so its includers also get PngFilter, PngBand and
// assemble_png.
//
// Filtering: every scanline of a band may only refer to rows the decoder will have decoded
// before it, which is always true inside the band. The first row of a band refers to nothing
// above it unless the caller passes the previous image row (`previous_row`), so bands never
// depend on another band's bytes, only (optionally) on one row of pixels.
//
// Default filter and strategy (PngBandOptions): Sub + PngStrategy::kRuns, Lantern's own
// literal + byte-run deflate encoder (run_deflate.h). It finds what zlib's Z_RLE finds (runs at
// distance 1), so files are the same size (1668 vs 1670 KiB on a 1 M-atom 1024^2 render), at
// 4.3x zlib's speed (9.4-9.5 vs 40-42 ms, RGBA, one thread, lantern-bench-png). The zlib
// strategies stay available: {kNone, kDefault} (LZ77) gives 0.71x of OpenImageIO's size on
// one-color crystals, whose repeated sphere sprites LZ77 exploits, at ~6x the time of the
// default. Up /
// Average are as fast and ~2% smaller but want `previous_row`; Paeth costs ~1.5x; Sub needs no
// row above, so bands need no halo row.
//
// Ownership: the functions read the caller's pixels during the call only and return buffers
// the caller owns. Thread-safety: pure functions without shared state; call them from any
// thread, concurrently. Errors: both return a Status and never throw.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/output/png/png_container.h"
#include "core/output/png/png_filters.h"

namespace lantern {

// kRuns: Lantern's own literal + byte-run encoder (run_deflate.h), the default; the others are
// zlib strategies (deflateInit2): Z_DEFAULT_STRATEGY, Z_FILTERED, Z_RLE, Z_HUFFMAN_ONLY.
enum class PngStrategy { kRuns, kDefault, kFiltered, kRle, kHuffmanOnly };

struct PngBandOptions {
  // The filter of every row. A band's first row without `previous_row` uses Sub instead of
  // Up / Average / Paeth (None stays None), so it never refers to a row the band does not have.
  PngFilter filter = PngFilter::kSub;
  PngStrategy strategy = PngStrategy::kRuns;
};

// What Lantern's PNG writer uses at a compression level: level 1 (the fastest, and the default)
// Sub + kRuns; any other level Sub + zlib's Z_RLE at that level, as before kRuns existed.
PngBandOptions png_options_for_level(int level);

// Compresses `rows` rows of RGBA8 pixels (`rgba`: row stride width * 4 bytes, top row first)
// as PNG scanlines (filter byte + filtered bytes of RGB when channels_out == 3, dropping alpha,
// or of RGBA when 4). The piece ends with Z_SYNC_FLUSH, or with Z_FINISH when `last_band`, so
// the pieces of consecutive bands, in order, form one deflate stream. `level` is the zlib
// level 0..9. `previous_row`: the RGBA8 row just above the band (width * 4 bytes) or nullptr;
// only Up / Average / Paeth use it. rows == 0 is allowed (an empty piece).
// Replaces *band and returns OK; else leaves *band empty and returns kInvalidArgument (width < 1,
// rows < 0, channels_out not 3 or 4, level outside 0..9, rgba null with rows > 0, band null),
// kOutOfMemory, or kInternal (zlib failed).
Status deflate_png_band(const uint8_t *rgba, int width, int rows, int channels_out, bool last_band,
                        int level, PngBand *band, const uint8_t *previous_row = nullptr,
                        const PngBandOptions &options = {});

// The whole image in one call: splits `rgba` (width x height RGBA8, top row first) into
// min(threads, height) bands of near-equal row counts, compresses them on that many threads
// (the calling thread included; threads <= 1 runs sequentially) and assembles the file. Each
// band gets its previous row, so every filter is usable. Replaces *file with the PNG file's
// bytes and returns OK; on failure leaves *file empty and returns kInvalidArgument (bad
// arguments), kOutOfMemory (no memory or thread) or kInternal (zlib failed).
Status encode_png(const uint8_t *rgba, int width, int height, int channels_out, int level,
                  int threads, std::vector<uint8_t> *file, const PngBandOptions &options = {});

}  // namespace lantern
