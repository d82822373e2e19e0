#include "core/composite/method_table.h"

namespace lantern {
namespace {

// Measured with tests/bench/composite.sh / lantern-bench-composite on the 2-core dev VM (Open MPI
// 4.1 shared memory; 3..8 ranks oversubscribed), 2026-11-22, medians in ms:
//
//   size        ranks  reduce64  reduce_scatter  binary_swap  direct_send
//   128x128     2/4/8  0.04/0.14/0.45      -      0.05/0.23/0.62  0.05/0.26/1.00  latency-bound:
//   256x256     2/4/8  0.29/1.0/11.4       -      0.42/7.2/15.9   0.42/7.4/24.3   one collective
//   512x512     2/4/8  0.81/8.4/29.7       -      0.47/2.8/14.2   0.40/6.1/15.0
//   1024x1024   2      3.98      11.3            2.31         2.32        (idle machine)
//   1920x1080   2      7.58      16.5            5.38         5.54        (idle machine)
//   4096x4096   2      129       173             72.6         73.9        (idle machine)
//   6144x3072   2      67.1      129             48.1         56.5        (idle machine)
//   1024x1024   8      60.8      80.8            28.2         33.4
//   1920x1080   3/6    32.5/162  -               28.0/64.0    28.2/62.0
//   4096x4096   3/6    499/1295  -               306/1102     451/1259
//
// Above ~64 Ki pixels the in-place binary swap wins almost everywhere, including rank counts that
// are not a power of two (3, 6), where its fold costs one extra full-frame message: direct
// send's p-1 steps cost more than that once ranks share cores. reduce64 beat it only for 4096^2
// and 6144x3072 at 4-8 oversubscribed ranks in one of four full runs (e.g. 230 vs 309 ms), which
// is within this shared machine's noise, so the table keeps one rule.
// reduce_scatter (Open MPI's default reduce_scatter_block) never won.
constexpr size_t kLatencyBoundPixels = size_t(256) * 256;

}  // namespace

CompositeMethod auto_composite_method(int /*ranks*/, size_t pixels) {
  return pixels <= kLatencyBoundPixels ? CompositeMethod::kReduce64 : CompositeMethod::kBinarySwap;
}

}  // namespace lantern
