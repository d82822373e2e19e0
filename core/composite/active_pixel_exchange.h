// One phase of active-pixel compositing: this rank streams ranges of its frame, run-length
// encoded (run_length_pixels.h), to some ranks while receiving ranges from others and merging
// (or writing) them into its frame. Every stream is cut into messages of bounded size; all of a
// rank's streams advance in lockstep, one message each per step under one MPI_Waitall, so no
// rank waits for a message its partner has not reached, and scratch stays bounded whatever the
// frame size.
//
// The matching call on the other side must name the same range: a receiver's incoming range is
// its sender's outgoing range. Messages use the tag given; callers give each phase its own tag.
//
// A stream's message bound must be the same on both of its ends, or the sender's message would
// overflow the receiver's buffer (MPI_ERR_TRUNCATE). So it is never derived from what one rank
// sees locally (its own stream count, its scratch's capacity, which only grows): it is the share
// of the agreed pool (ActivePixelScratch::pool_words) for the phase's agreed stream count, capped
// by the stream's range - the same numbers on sender and receiver.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <vector>

#include "core/common/status.h"
#include "core/common/uninitialized_buffer.h"
#include "core/composite/active_pixels.h"
#include "core/composite/composite_traffic.h"
#include "core/composite/pixel_range.h"
#include "core/composite/run_length_pixels.h"

namespace lantern {

// The most words a pool holds (2 MiB): a 1024 x 1024 frame's half moves in one message per
// stream. With 256 KiB pools its 5 messages were encoded into lines the partner had just read
// (MPI's single-copy transfer reads the sender's buffer from the other core), and about half of
// the runs of the 1 M-atom LJ frame then took 1.6 ms of compositing CPU time instead of 1.1 (the
// encoder's stores waiting); with one message per stream, 1.1-1.2 ms in 5 runs of 5
// (tests/bench/culling/results/base_rows_ab.txt). Callers hold the pool for one call only, so it
// is not kept resident between frames: its pages are lazily freed for the next frame's
// (core/common/page_allocator.h).
inline constexpr size_t kActivePoolWords = size_t(1) << 18;

// Message buffers, carved per phase among the streams: pool_words each for sending and receiving.
struct ActivePixelScratch {
  // At least pool_words each (prepare only grows them).
  UninitializedBuffer<uint64_t> send, receive;
  // This call's pool: a function of (chunk_pixels, ranks) only, so the same on every rank once
  // those are agreed, however large the buffers grew in earlier calls.
  size_t pool_words = 0;
  // Sets pool_words to about chunk_pixels encoded pixels, at most kActivePoolWords, and at least
  // a minimal message for each of `ranks` streams, and grows both buffers to hold it. May throw
  // std::bad_alloc.
  void prepare(size_t chunk_pixels, int ranks);
};

struct OutgoingRange {
  int to = 0;
  PixelRange range;
};
struct IncomingRange {
  int from = 0;
  PixelRange range;
};

// Streams every `outgoing` range of frame to its rank while merging every `incoming` range's
// messages into frame. Empty ranges send nothing. `streams` is the phase's stream count, the same
// on every rank: at least the outgoing and the incoming ranges of any one rank in this phase
// (each stream's messages are at most max(kMinMessageWords, pool_words / streams) words, and
// at most its range's size + 2; a plan that gives one rank more streams than `streams` has its
// messages cut for that rank's count, so scratch is never overrun). Adds what moved to *traffic.
// OK, kMpi with the MPI error, or kInternal for a malformed message (the protocol still runs to
// its end).
Status exchange_active_pixels(MPI_Comm comm, int tag, size_t streams,
                              const std::vector<OutgoingRange> &outgoing,
                              const std::vector<IncomingRange> &incoming, ActiveFrame &frame,
                              ActivePixelScratch &scratch, CompositeTraffic *traffic);

}  // namespace lantern
