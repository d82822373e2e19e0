// A range of a frame's pixels as compositing sends it: only the active pixels (active_pixels.h),
// with the runs of empty ones between them counted instead of sent - IceT's run-length encoded
// sparse image (Moreland et al., "An Image Compositing Solution at Scale", SC 2011), cut into
// messages of bounded size so that scratch memory stays bounded whatever the frame size.
//
// A message is a sequence of 64-bit words:
//   word 0           pixels of the range this message covers (low 63 bits); bit 63 set on the
//                    range's last message
//   then, repeated:  a run pair, (empty pixels to skip) << 32 | (active pixels that follow),
//                    followed by that many packed keys (packed_pixel.h)
// Pixels of the covered span after the last run are empty. A range of R pixels takes at most
// 8 R + 16 bytes in all (never more than the dense 8 R bytes plus one pair and a header), and a
// range with nothing active takes one 8-byte word.
//
// The encoder only looks inside the frame's active rectangle: rows and columns outside it are
// skipped without being read (they are known to be empty).
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/common/status.h"
#include "core/composite/active_pixels.h"
#include "core/composite/pixel_range.h"

namespace lantern {

// Smallest message capacity (words): a header, a run pair and one key.
inline constexpr size_t kMinMessageWords = 3;

// Writes one range of a frame as successive messages.
class RunLengthEncoder {
 public:
  explicit RunLengthEncoder(PixelRange range) : range_(range), next_(range.lo) {}

  // Encodes the next message into out[0, capacity) (capacity >= kMinMessageWords) and returns its
  // length in words. Call until done().
  size_t encode(const ActiveFrame &frame, uint64_t *out, size_t capacity);
  bool done() const { return done_; }

 private:
  PixelRange range_;
  size_t next_;  // first pixel not yet covered
  bool done_ = false;
};

// Merges one range's successive messages into a frame by compositing's rule: active pixels are
// merged, empty ones leave the frame alone (min(x, E) = x).
class RunLengthDecoder {
 public:
  explicit RunLengthDecoder(PixelRange range) : range_(range), next_(range.lo) {}

  // Merges message[0, words) into frame's pixels and grows frame.rect by the pixels merged in.
  // kInternal if the message does not fit the range (a bug or a corrupted message).
  Status decode(const uint64_t *message, size_t words, ActiveFrame &frame);
  bool done() const { return done_; }

 private:
  PixelRange range_;
  size_t next_;
  bool done_ = false;
};

}  // namespace lantern
