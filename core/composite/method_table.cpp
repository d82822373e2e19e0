#include "core/composite/method_table.h"

namespace lantern {
namespace {

// Measured with tests/bench/composite.sh and lantern-bench-composite (2-core VM, Open MPI 4.1
// shared memory, 2..8 ranks oversubscribed, 2026-11-22; medians of 9 runs, in ms):
//
//   pixels      ranks  reduce64  binary_swap  direct_send
//   128x128     2/4/8  0.04/0.14/0.45  0.05/0.23/0.62  0.05/0.26/1.00   latency-bound: one
//   256x256     2/4/8  0.29/1.0/11.4   0.42/7.2/15.9   0.42/7.4/24.3    collective wins
//   512x512     2/4/8  0.81/8.4/29.7   0.47/2.8/14.2   0.40/6.1/15.0
//   1024x1024   2      4.7             2.7-3.3         (= binary swap at 2 ranks)
//   1920x1080   3/6    32.5/162        28.0/64.0       28.2/62.0
//   4096x4096   3/6    499/1295        306/1102        451/1259
//
// Above ~64 Ki pixels the in-place binary swap wins at every rank count, including the
// non-power-of-two ones (3, 6) where its fold costs an extra full-frame message: direct send's
// p-1 steps cost more than that once ranks share cores. reduce_scatter (Open MPI's default
// reduce_scatter_block) was 2-4x slower than reduce64 everywhere and is never chosen.
constexpr size_t kLatencyBoundPixels = size_t(256) * 256;

}  // namespace

CompositeMethod auto_composite_method(int /*ranks*/, size_t pixels) {
  return pixels <= kLatencyBoundPixels ? CompositeMethod::kReduce64 : CompositeMethod::kBinarySwap;
}

}  // namespace lantern
