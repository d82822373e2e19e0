// PNG output with the compression spread over threads or the ranks of a communicator: a frame
// is cut into a fixed number of row bands (a function of its height only), each band is
// deflated on its own (png_bands.h), and the pieces are joined into one file written atomically
// (atomic_file.h). Because the bands do not depend on who compresses them, a frame gives the
// same file bytes on any number of ranks, threads, synchronous or asynchronous, and whether the
// rows were the root's, handed out for compression (write_png_across_ranks), or already where
// compositing left them, one row band per rank (write_png_from_row_bands).
//
// Measured (lantern-bench-png --image, a 1 M-atom LJ frame at 1024x1024, level 1,
// tests/bench/png/results/run_encoder_checksums_ab.txt): one libpng stream through OpenImageIO
// 93-107 ms; these bands on one thread 6.8-7.6 ms (RGB); the slower of 2 bands plus the root's
// assembly 5.0-5.3 ms (RGBA).
//
// Ownership: the functions read the frame during the call. Never throw.
#pragma once

#include <mpi.h>

#include <string>

#include "core/common/status.h"
#include "core/view/frame.h"

namespace lantern {

// Row bands of every PNG Lantern writes for an image `height` rows high.
int png_band_count(int height);

// Writes `frame` to `path` as an 8-bit PNG at zlib `level` (RGB when every pixel is opaque, as
// Lantern's frames are; RGBA otherwise), compressing on up to `threads`
// threads of this process. Returns OK or kIo with a message naming the path (every failure,
// encoding included, is a file that cannot be written).
Status write_png(const Frame &frame, int level, const std::string &path, int threads);

// Collective over `comm` (same width, height and level on every rank), same files as write_png:
// the root's `frame` is scattered in rows, every rank compresses its share of the bands and
// sends each band on as soon as it is compressed, and the root writes `path` band by band as
// they come (PngBandStream), so writing overlaps the other ranks' compression. `threads`: how
// many threads of this process may compress (on one rank: write_png's; on several: the root's
// own bands - the other ranks take their rows a band at a time, on one). `frame` and `path`
// matter on root only. Returns OK or, on root, kIo naming the path (a rank whose compression
// failed also reports it; the others still finish the call).
Status write_png_across_ranks(MPI_Comm comm, int root, const Frame &frame, int width, int height,
                              int level, const std::string &path, int threads = 1);

// The rows of each of a PNG's bands (png_band_count) for an image of width x height, when every
// band has as many and a band's bytes are well within one MPI message; 0 otherwise (then
// write_png_from_row_bands cannot be used).
int png_band_rows(int height, int width);

// Collective over `comm`, the same file as write_png from an image that is already spread over
// the ranks in row bands (compositing left it so, core/finish/finish_image.h): rank k holds image
// rows [y0, y1) at `rows` (width x (y1 - y0) RGBA8 pixels, top row first), the ranks' rows in rank
// order cover the image, and every y0 and y1 is a multiple of png_band_rows(height, width) (a
// rank may hold none). Each rank compresses the bands it holds, on up to `threads` threads of
// its process, and sends them to the root, which writes `path` band by band as they come: no
// pixel moves, only compressed bands. Besides that, one small MPI_Allgather (the bands and
// whether each rank's rows are opaque: RGB or RGBA). Only the calling thread makes MPI calls.
// Returns OK or, on root, kIo naming the path (as write_png_across_ranks); kInvalidArgument on
// every rank when the rows are not such bands.
Status write_png_from_row_bands(MPI_Comm comm, int root, const uint8_t *rows, int y0, int y1,
                                int width, int height, int level, const std::string &path,
                                int threads = 1);

}  // namespace lantern
