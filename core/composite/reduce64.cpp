// Compositing by MPI_Reduce(MPI_MIN) on packed 64-bit pixels: MPI chooses the reduction tree.
//
// Pixels are packed one chunk at a time, so scratch is one chunk and MPI's own temporaries stay
// chunk-sized however large the frame is (and the int count of MPI_Reduce never overflows).
#include <algorithm>

#include "core/composite/composite_methods.h"
#include "core/composite/packed_pixel.h"

namespace lantern {

Status composite_reduce64(MPI_Comm comm, Frame &frame, int root, MethodScratch &scratch,
                          CompositeTraffic *traffic) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const size_t pixels = frame.pixel_count();
  const size_t chunk = scratch.packed.size();
  uint64_t *buffer = scratch.packed.data();
  for (size_t first = 0; first < pixels; first += chunk) {
    const size_t count = std::min(chunk, pixels - first);
    pack_pixels(frame, first, count, buffer);
    // In place on root: its own chunk is both an input and the result.
    const void *send = rank == root ? MPI_IN_PLACE : buffer;
    const int rc = MPI_Reduce(send, buffer, int(count), MPI_UINT64_T, MPI_MIN, root, comm);
    if (rc != MPI_SUCCESS) return mpi_error(rc, "MPI_Reduce");
    if (rank == root) unpack_pixels(buffer, first, count, frame);
    // What this rank hands to MPI and gets back (the tree's own traffic is MPI's).
    (rank == root ? traffic->bytes_received : traffic->bytes_sent) += 8 * uint64_t(count);
    ++(rank == root ? traffic->messages_received : traffic->messages_sent);
  }
  return {};
}

}  // namespace lantern
