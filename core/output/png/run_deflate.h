// A deflate (RFC 1951) encoder specialised for PNG scanlines: literals plus runs of a repeated
// byte (matches at distance 1, what zlib's Z_RLE strategy looks for), one dynamic Huffman block
// per call. It does in one pass what zlib's Z_RLE does in its general machinery (hash-free, but
// still through zlib's per-byte state machine), at several times the speed and about the same
// size on sphere renders, which makes it the default for Lantern's PNGs (lantern-bench-png
// compares it with every zlib strategy).
//
// Pieces: `RunDeflater` writes raw deflate blocks into its own buffer. A piece that does not end
// the stream ends with an empty stored block, as zlib's Z_SYNC_FLUSH does, so it stops on a byte
// boundary and the pieces of consecutive bands concatenate into one deflate stream. Matches
// never reach back before the block's first byte, so every block decodes on its own window.
//
// Ownership: the deflater owns its output until take(). Thread-safety: one object per thread;
// no shared state. Errors: only std::bad_alloc.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/common/page_allocator.h"
#include "core/common/uninitialized_buffer.h"

namespace lantern {

class RunDeflater {
 public:
  // Room for a piece of about `input_bytes` input bytes, asked before the first block: the output
  // then grows in place, where growing by a quarter at a time moved (and faulted in) about three
  // times the piece's bytes. Only address space until written (mapped pages, page_allocator.h).
  // Optional: without it, or past it, the output grows as before. Changes no byte.
  void expect(size_t input_bytes);
  // Compresses `n` bytes as one block (nothing for n == 0); `final` sets the block's BFINAL.
  void add_block(const uint8_t *data, size_t n, bool final);
  // Ends the piece on a byte boundary: after a final block by padding, otherwise with an empty
  // stored block (an empty final block first, when the stream is to end but no block was final).
  void finish(bool end_of_stream);
  // The compressed bytes so far; the deflater is empty afterwards.
  PageVector<uint8_t> take();

 private:
  void reserve(size_t bytes);  // room for `bytes` more output bytes
  void put(uint64_t bits, int count);
  void align();

  // The first used_ bytes are output. Mapped pages from kPageBlockBytes on, as tokens_: a band's
  // buffers are freed once it is written, and would otherwise stay in the heap between frames.
  PageVector<uint8_t> out_;
  size_t used_ = 0;
  uint64_t acc_ = 0;  // pending bits, least significant first
  int pending_ = 0;   // how many
  bool ended_ = false;
  UninitializedBuffer<uint16_t> tokens_;  // literal byte, or 256 + run length (written first)
};

}  // namespace lantern
