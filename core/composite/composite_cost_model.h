// What compositing will cost, before it runs: messages x latency + bytes / bandwidth on the
// busiest rank, for each candidate schedule (compositing_schedule.h), so that the cheapest one
// is chosen per frame - from what every rank agreed on (the frame size, the rank count, the most
// active pixels any rank holds) and one model that is the same on every rank, so every rank picks
// the same schedule without a further message.
//
// The model's transport figures come from measure_cost_model: a ping-pong between rank 0 and the
// last rank (in a job laid out node by node, the pair furthest apart), 8-byte messages for the
// latency and 1 MiB ones for the bandwidth, the shortest of several round trips (on shared cores
// the others hold waits for a core), the other ranks asleep meanwhile; rank 0's figures are
// broadcast, so every rank holds the same bits. The pipeline measures once per context, at its
// first compositing on two or more ranks, and keeps the model for the context's lifetime (each
// stats line reports it). Without a measurement default_cost_model() stands in: the figures
// measured on the development machine (2-core VM, Open MPI 4.1 shared memory).
//
// What the active-pixel estimate assumes (the bench prints this with its extrapolation):
// - every rank has `active` active pixels (the busiest rank's count), spread evenly over the
//   frame, and the ranks' drawn pixels do not overlap, so after merging K ranks' images a region
//   holds min(1, K * active / pixels) of its pixels active (overlap only makes it fewer);
// - 8 bytes per active pixel; run-length pairs and headers (8 bytes per run) are left out;
// - a rank's k - 1 messages of a round are sent and received concurrently: one latency per
//   message, bytes at the bandwidth, the busiest rank's bytes per round on the critical path;
// - gathering on the root: q - 1 messages and (q - 1) / q of the merged frame's active pixels;
//   handing the bands back after folding: one message;
// - the tree reduce: one message per round on the root's path, round j's frame holding 2^j
//   ranks' images;
// - CPU time, per pixel, from the four figures measured with the rest (measure_cost_model times
//   each on a synthetic half-covered frame on rank 0, thread CPU time, medians of several runs):
//   every rank scans its whole frame once; in an exchange a rank encodes what it sends and merges
//   what it receives, one after the other; a one-way stream (a fold, a tree round, the root's
//   gather) costs the slower of the two ends, the sender's encoding overlapping the receiver's
//   merging message by message (at the root's gather, the senders encode their blocks side by
//   side while the root merges them all). Run-length headers, the search over empty runs inside the
//   active rectangle and MPI's own copies (those are in the bandwidth) are left out.
//
// Dense compositing (every pixel sent, no scan) is priced the same way, so that kAuto can keep the
// dense binary swap where it is faster (few ranks, large drawn areas): log2 q rounds of half the
// region, each pixel received merged (dense_merge_s), the root's gather written in place by MPI
// (bytes only). MPI_Reduce (reduce64) as a binomial tree: ceil(log2 p) rounds of the whole frame
// on the root's path, each costing a dense merge per pixel (MPI's MIN over packed keys; packing
// and unpacking left out).
#pragma once

#include <mpi.h>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/composite/compositing_schedule.h"

namespace lantern {

struct CompositeCostModel {
  double latency_s = 0.0;    // one message, seconds
  double bytes_per_s = 0.0;  // sustained point-to-point bandwidth
  bool measured = false;     // false: default_cost_model()'s figures
  // CPU seconds per pixel (0: not priced).
  double scan_s = 0.0;         // scanning a frame for its active pixels, per frame pixel
  double encode_s = 0.0;       // run-length encoding, per active pixel sent
  double merge_s = 0.0;        // merging a received active pixel
  double dense_merge_s = 0.0;  // merging a received pixel of a dense exchange
};

CompositeCostModel default_cost_model();

// Collective over comm (two or more ranks): measures the model (see above) and returns it on every
// rank, identical. Takes a few milliseconds on shared memory. OK or kMpi.
Status measure_cost_model(MPI_Comm comm, CompositeCostModel *model);

// A fingerprint of the model and of a forced schedule, for checking that every rank passed the
// same ones (schedules are chosen from them).
long long cost_model_fingerprint(const CompositeCostModel &model,
                                 const std::optional<CompositingSchedule> &forced);

// The busiest rank's predicted cost.
struct CostEstimate {
  double seconds = 0.0;
  double bytes_sent = 0.0;     // by the busiest sender, all phases
  double messages_sent = 0.0;  // by the busiest sender, all phases
};

// Active-pixel compositing of a frame of `pixels` pixels, at most `active` active on any rank,
// with `schedule`, ending on one root (to_root) or in row bands.
CostEstimate estimate_active_pixels(const CompositingSchedule &schedule, size_t pixels,
                                    size_t active, bool to_root, const CompositeCostModel &model);

// MPI_Reduce of every packed pixel to the root (the reduce64 method), as a binomial tree:
// ceil(log2 p) rounds of the whole frame on the root's path.
CostEstimate estimate_reduce64(int ranks, size_t pixels, const CompositeCostModel &model);

// Dense binary swap to the root (the binary_swap method): ranks beyond the largest power of two
// q fold first, log2 q rounds of half the region, the gather of q blocks on the root.
CostEstimate estimate_dense_binary_swap(int ranks, size_t pixels, const CompositeCostModel &model);

// The cheapest of candidate_schedules(ranks) under the model (the first one on a tie).
CompositingSchedule cheapest_schedule(int ranks, size_t pixels, size_t active, bool to_root,
                                      const CompositeCostModel &model, CostEstimate *estimate);

}  // namespace lantern
