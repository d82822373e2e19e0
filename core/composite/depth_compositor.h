// Sort-last depth compositing over MPI: every rank renders its own particles into a Frame, and
// the frames are merged pixel by pixel by nearest depth into one image on a root rank.
//
// Merge rule (see packed_pixel.h): the smaller window depth wins; on equal depth the smaller
// color (R, then G, B, A) wins. The rule is commutative and associative, so the merged image
// is bit-identical for any rank count, any split of the particles and every method below.
//
// Methods: active pixels (the default, active_pixel_compositing.h) sends only the pixels a rank
// drew, run-length encoded, along a radix-k schedule chosen per frame by a cost model
// (composite_cost_model.h); the dense methods move every pixel (kept for comparison and for
// tiny frames, where one MPI_Reduce is cheapest).
//
// Collective: every rank of comm calls composite_frames with the same width, height, root and
// options. Problems found before any pixel moves (mismatched sizes, bad root, disagreeing options
// or cost models, out of memory) are agreed in one MPI_Allreduce and returned as the same kMpi
// status on every rank (the collective could not run), so no rank throws or is left waiting. An
// MPI failure inside a method follows comm's error handler (fatal by default); under
// MPI_ERRORS_RETURN it is returned (kMpi) on that rank.
//
// Memory: besides the Frame itself, a rank holds about two chunks of scratch (16 MiB at the
// default chunk) whatever the frame size: reductions pack and reduce one chunk at a time, the
// point-to-point methods merge into the frame in place, receiving at most a chunk per step.
// The scratch is kept per thread between calls, so steady-state frames do not allocate.
// Limit: at most INT_MAX / 4 pixels (MPI counts are int; 8192 x 8192 is 1/8 of that).
#pragma once

#include <mpi.h>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/composite/composite_cost_model.h"
#include "core/composite/composite_traffic.h"
#include "core/composite/compositing_schedule.h"
#include "core/view/frame.h"

namespace lantern {

enum class CompositeMethod {
  kAuto,           // the cost model's cheapest: active pixels, or reduce64 for tiny frames
  kReduce64,       // pack depth+RGBA in one uint64, MPI_Reduce(MPI_MIN) in chunks to root
  kReduceScatter,  // MPI_Reduce_scatter_block(MPI_MIN) + MPI_Gather to root, in chunks
  kBinarySwap,     // dense binary swap in place; extra ranks (non power of 2) fold in first
  kDirectSend,     // dense pairwise-exchange reduce-scatter in place + gather to root
  kActivePixels,   // active pixels only, along the model's cheapest radix-k schedule
};

// "auto", "reduce64", "reduce_scatter", "binary_swap", "direct_send", "active_pixels"; stats say
// "none" for one rank.
const char *to_string(CompositeMethod method);
// Parses the names above (not "none"); returns false and leaves *method alone if unknown.
bool parse_composite_method(const std::string &name, CompositeMethod *method);

// Reductions move at most this many pixels per MPI call (8 MiB of packed pixels).
inline constexpr size_t kDefaultCompositeChunkPixels = size_t(1) << 20;

struct CompositeOptions {
  CompositeMethod method = CompositeMethod::kAuto;
  size_t chunk_pixels = 0;  // pixels per MPI call or message (0 = kDefaultCompositeChunkPixels)
  // The model schedules are chosen by; null: default_cost_model(). Must be the same on every rank
  // (measure_cost_model gives every rank the same one).
  const CompositeCostModel *model = nullptr;
  // kActivePixels: run this schedule (compositing_schedule.h) instead of the model's choice
  // (tests, benchmarks); none: the model chooses.
  std::optional<CompositingSchedule> schedule;
};

struct CompositeStats {
  std::string method;         // the method actually run ("none" on one rank, never "auto")
  std::string schedule;       // active pixels: the schedule run, e.g. "binary_swap", "radix_k 4x2"
  double milliseconds = 0.0;  // wall time of this rank inside compositing
  double model_ms = 0.0;      // the cost model's estimate for what ran (busiest rank)
  int ranks = 0;
  size_t pixels = 0;
  size_t active_pixels = 0;  // active pixels: this rank's, before compositing
  CompositeTraffic traffic;  // this rank's messages, bytes and CPU time of its own work
};

// Merges every rank's frame into frame on root (see the rule above). On return frame on root
// holds the merged color and depth; frames on other ranks are unspecified. With one rank this is
// a no-op. Returns OK or kMpi (see above); fills *stats, if not null, either way.
Status composite_frames(MPI_Comm comm, Frame &frame, int root, const CompositeOptions &options,
                        CompositeStats *stats = nullptr);

// The same with a method and chunk only.
inline Status composite_frames(MPI_Comm comm, Frame &frame, int root,
                               CompositeMethod method = CompositeMethod::kAuto,
                               size_t chunk_pixels = 0, CompositeStats *stats = nullptr) {
  CompositeOptions options;
  options.method = method;
  options.chunk_pixels = chunk_pixels;
  return composite_frames(comm, frame, root, options, stats);
}

}  // namespace lantern
