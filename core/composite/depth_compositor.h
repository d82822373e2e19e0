// Sort-last depth compositing over MPI: every rank renders its own particles into a Frame, and
// the frames are merged pixel by pixel by nearest depth into one image on a root rank.
//
// Merge rule (see packed_pixel.h): the smaller window depth wins; on equal depth the smaller
// color (R, then G, B, A) wins. The rule is commutative and associative, so the merged image
// is bit-identical for any rank count, any split of the particles and every method below.
//
// Collective: every rank of comm calls composite_frames with the same width, height, root and
// method. Problems found before any pixel moves (mismatched sizes, bad root, disagreeing method,
// out of memory) are agreed in one MPI_Allreduce and returned as the same kMpi status on every
// rank (the collective could not run), so no rank throws or is left waiting. An MPI failure
// inside a method follows comm's error handler (fatal by default); under MPI_ERRORS_RETURN it is
// returned (kMpi) on that rank.
//
// Memory: besides the Frame itself, a rank holds about two chunks of scratch (16 MiB at the
// default chunk) whatever the frame size: reductions pack and reduce one chunk at a time (so
// MPI's own temporaries stay chunk-sized too) and the point-to-point methods merge into the
// frame in place, receiving one chunk-sized segment at a time.
// The scratch is kept per thread between calls, so steady-state frames do not allocate.
// Limit: at most INT_MAX / 4 pixels (MPI counts are int; 8192 x 8192 is 1/8 of that).
#pragma once

#include <mpi.h>

#include <cstddef>
#include <string>

#include "core/common/status.h"
#include "core/view/frame.h"

namespace lantern {

enum class CompositeMethod {
  kAuto,           // the measured-fastest method for (ranks, pixels): see method_table.cpp
  kReduce64,       // pack depth+RGBA in one uint64, MPI_Reduce(MPI_MIN) in chunks to root
  kReduceScatter,  // MPI_Reduce_scatter_block(MPI_MIN) + MPI_Gather to root, in chunks
  kBinarySwap,     // hand-written binary swap in place; extra ranks (non power of 2) fold in first
  kDirectSend,     // hand-written pairwise-exchange reduce-scatter in place + gather to root
};

// "auto", "reduce64", "reduce_scatter", "binary_swap", "direct_send"; stats say "none" for one
// rank.
const char *to_string(CompositeMethod method);
// Parses the names above (not "none"); returns false and leaves *method alone if unknown.
bool parse_composite_method(const std::string &name, CompositeMethod *method);

struct CompositeStats {
  std::string method;         // the method actually run ("none" on one rank, never "auto")
  double milliseconds = 0.0;  // wall time of this rank inside composite_frames
  int ranks = 0;
  size_t pixels = 0;
};

// Reductions move at most this many pixels per MPI call (8 MiB of packed pixels).
inline constexpr size_t kDefaultCompositeChunkPixels = size_t(1) << 20;

// Merges every rank's frame into frame on root (see the rule above). On return frame on root
// holds the merged color and depth; frames on other ranks are unspecified. With one rank this is
// a no-op. chunk_pixels bounds the pixels per MPI call (0 = kDefaultCompositeChunkPixels).
// Returns OK or kMpi (see above); fills *stats, if not null, either way.
Status composite_frames(MPI_Comm comm, Frame &frame, int root,
                        CompositeMethod method = CompositeMethod::kAuto, size_t chunk_pixels = 0,
                        CompositeStats *stats = nullptr);

}  // namespace lantern
