// Hand-written direct send (a pairwise-exchange reduce-scatter), merging the frames in place.
//
// Rank i owns the i-th of p equal pixel blocks. In step s = 1..p-1 it sends block (i+s) mod p to
// its owner and merges the copy of block i that rank (i-s) mod p sends. Then root gathers the
// blocks. Unlike binary swap it needs no folding for rank counts that are not a power of two
// (every rank merges 1/p of the image), at the price of p-1 steps instead of log2(p).
#include <vector>

#include "core/composite/composite_methods.h"
#include "core/composite/pixel_exchange.h"

namespace lantern {

Status composite_direct_send(MPI_Comm comm, Frame &frame, int root, MethodScratch &scratch,
                             CompositeTraffic *traffic) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const size_t pixels = frame.pixel_count(), p = size_t(ranks);
  std::vector<PixelRange> blocks(p);
  for (size_t i = 0; i < p; ++i) blocks[i] = {pixels * i / p, pixels * (i + 1) / p};
  Status error;
  for (int step = 1; step < ranks && error.ok(); ++step) {
    const int to = (rank + step) % ranks, from = (rank - step + ranks) % ranks;
    error = exchange_and_merge(comm, to, blocks[size_t(to)], from, blocks[size_t(rank)], frame,
                               scratch, traffic);
  }
  Status gather_error = gather_ranges(comm, root, blocks, frame, traffic);
  return error.ok() ? gather_error : error;
}

}  // namespace lantern
