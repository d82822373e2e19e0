// Compositing by MPI_Reduce_scatter_block(MPI_MIN) then MPI_Gather to root, one chunk at a time.
//
// Every rank reduces 1/p of each chunk (the merge work is spread), then root collects the blocks.
// A chunk is padded to a multiple of p with the neutral key UINT64_MAX.
#include <algorithm>
#include <cstdint>

#include "core/composite/composite_methods.h"
#include "core/composite/packed_pixel.h"

namespace lantern {

Status composite_reduce_scatter(MPI_Comm comm, Frame &frame, int root, MethodScratch &scratch,
                                CompositeTraffic *traffic) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const size_t pixels = frame.pixel_count();
  const size_t chunk = scratch.packed.size();  // a multiple of ranks
  uint64_t *packed = scratch.packed.data();
  uint64_t *block = scratch.block.data();
  for (size_t first = 0; first < pixels; first += chunk) {
    const size_t count = std::min(chunk, pixels - first);
    const size_t block_size = (count + size_t(ranks) - 1) / size_t(ranks);
    pack_pixels(frame, first, count, packed);
    std::fill(packed + count, packed + block_size * size_t(ranks), UINT64_MAX);
    int rc = MPI_Reduce_scatter_block(packed, block, int(block_size), MPI_UINT64_T, MPI_MIN, comm);
    if (rc != MPI_SUCCESS) return mpi_error(rc, "MPI_Reduce_scatter_block");
    if (rank == root) {
      // Root's own block goes where the gather would have put it, then is gathered in place.
      std::copy(block, block + block_size, packed + size_t(root) * block_size);
      rc = MPI_Gather(MPI_IN_PLACE, int(block_size), MPI_UINT64_T, packed, int(block_size),
                      MPI_UINT64_T, root, comm);
    } else {
      rc = MPI_Gather(block, int(block_size), MPI_UINT64_T, nullptr, 0, MPI_UINT64_T, root, comm);
    }
    if (rc != MPI_SUCCESS) return mpi_error(rc, "MPI_Gather");
    if (rank == root) unpack_pixels(packed, first, count, frame);
    // What this rank hands to MPI and gets back (the collectives' own traffic is MPI's): its
    // chunk in, its reduced block out, then the block to root (root: every block back).
    traffic->bytes_sent +=
        8 * uint64_t(block_size * size_t(ranks) + (rank == root ? 0 : block_size));
    traffic->bytes_received += 8 * uint64_t(block_size * (rank == root ? size_t(ranks) : 1));
    traffic->messages_sent += rank == root ? 1 : 2;
    traffic->messages_received += rank == root ? 2 : 1;
  }
  return {};
}

}  // namespace lantern
