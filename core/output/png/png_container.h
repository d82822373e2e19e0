// The PNG file container (PNG spec 5 and 11): the signature, chunks with their CRC, IHDR, IDAT
// chunks of at most 1 MiB and IEND, and the assembly of one file from the compressed pieces of an
// image's row bands (png_bands.h) without recompressing anything: the zlib header, the pieces back
// to back, and the zlib checksum combined from the pieces' adler32 values (adler32_combine).
//
// PngBand, the piece type, lives here rather than in png_bands.h because it is what assembly
// consumes, and png_bands.h builds on this file (compression uses the container, not the other
// way round).
//
// Ownership: assemble_png reads the caller's bands during the call and writes into the caller's
// buffer. Thread-safety: no shared state; call it from any thread, concurrently on different
// buffers. Errors: assemble_png never throws and returns a Status.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/common/page_allocator.h"
#include "core/common/status.h"

namespace lantern {

// One band's compressed piece and what the root needs to join it to the others.
struct PngBand {
  PageVector<uint8_t> bytes;  // raw deflate data (no zlib header or trailer), owned
  uint32_t adler = 1;         // adler32 of the band's uncompressed filtered scanlines
  uint64_t raw_len = 0;       // their length: rows * (1 + width * channels_out)
  int rows = 0;               // scanlines in the band
  bool last = false;          // ends the deflate stream (Z_FINISH)
};

// Lays out a PNG file from the bands of one image, top band first: signature, IHDR (8-bit,
// color type 2 for channels_out == 3 or 6 for 4, no interlace), IDAT chunks of at most
// 1 MiB holding the zlib header, the concatenated pieces and the combined adler32, then IEND.
// Replaces *file. Returns kInvalidArgument when the bands do not describe a width x height image
// (row count, raw length, only the last band finishing) or `file` is null, kOutOfMemory when the
// file does not fit in memory.
Status assemble_png(const std::vector<PngBand> &bands, int width, int height, int channels_out,
                    std::vector<uint8_t> *file);

// Receives a file's bytes in order, in pieces; false stops the file (an I/O error).
using PngSink = std::function<bool(const uint8_t *data, size_t n)>;

// The same bytes as assemble_png, handed to `put` in order without being gathered into one
// buffer: the bands' compressed pieces pass straight through (a file's worth of memory less at
// the root). Returns assemble_png's errors, or kIo when `put` returned false.
Status stream_png(const std::vector<PngBand> &bands, int width, int height, int channels_out,
                  const PngSink &put);

// Rewrites n bytes already handed to a PngSink, from file offset `offset`; false: an I/O error.
using PngPatch = std::function<bool(uint64_t offset, const uint8_t *data, size_t n)>;

// stream_png for bands that arrive one at a time (the root of write_png_across_ranks writes each
// band as soon as it has it, while other ranks still compress theirs): the same file bytes, with
// the compressed total unknown until finish(). Every IDAT chunk's length precedes its data and
// is announced as 1 MiB, which every chunk but the last holds; finish() corrects the last one's
// through `patch` (4 bytes). add() the bands top first, then finish(). Each returns stream_png's
// errors for what it has seen so far (kInvalidArgument for a band that does not fit, or for
// fewer bands or rows than announced at finish; kIo once `put` or `patch` returned false);
// after an error every call returns it and nothing more is put.
class PngBandStream {
 public:
  PngBandStream(int width, int height, int channels_out, int bands, PngSink put, PngPatch patch);
  ~PngBandStream();
  PngBandStream(const PngBandStream &) = delete;
  PngBandStream &operator=(const PngBandStream &) = delete;

  Status add(const PngBand &band);
  Status finish();

 private:
  struct State;
  int width_, height_, channels_, bands_;
  PngSink put_;
  PngPatch patch_;
  int added_ = 0;
  Status failure_;
  std::unique_ptr<State> state_;  // from the first add: the IDAT chunks so far
};

}  // namespace lantern
