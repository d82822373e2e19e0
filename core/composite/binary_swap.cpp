// Hand-written binary swap (Ma et al. 1994) on packed 64-bit pixels.
//
// With p ranks, let q be the largest power of two <= p. Ranks q..p-1 first fold their whole image
// into rank r - q; then the q base ranks run log2(q) rounds, each halving the region it owns and
// swapping the other half with its partner (rank ^ bit); finally root gathers the q pieces.
// Each rank merges only its share, so the merge work is spread over all ranks.
//
// Point-to-point messages use kTag on comm; a caller that sends its own messages on the same
// communicator should give compositing a duplicate (MPI_Comm_dup).
#include <algorithm>
#include <vector>

#include "core/composite/composite_methods.h"
#include "core/composite/packed_pixel.h"

namespace lantern {
namespace {

constexpr int kTag = 0x4c43;  // "LC"

struct Range {
  size_t lo = 0;
  size_t hi = 0;
  size_t size() const { return hi - lo; }
};

int largest_power_of_two_at_most(int n) {
  int q = 1;
  while (q * 2 <= n) q *= 2;
  return q;
}

// The pixels base rank `index` owns after every swap round among `base` ranks. Every rank can
// compute every rank's range, which is what the final gather needs.
Range owned_range(int index, int base, size_t pixels) {
  Range r{0, pixels};
  for (int bit = 1; bit < base; bit <<= 1) {
    const size_t mid = r.lo + r.size() / 2;
    if (index & bit) {
      r.lo = mid;
    } else {
      r.hi = mid;
    }
  }
  return r;
}

// Sends send[0, send_count) to partner while receiving the partner's pixels for
// keep[0, keep_count) and merging them in, one scratch-sized segment at a time. The partner calls
// it with the counts swapped, so both walk the same segments. Either count may be 0 (folding).
std::string swap_and_merge(MPI_Comm comm, int partner, const uint64_t *send, size_t send_count,
                           uint64_t *keep, size_t keep_count, PackedBuffer &scratch) {
  const size_t segment = scratch.size();
  const size_t total = std::max(send_count, keep_count);
  for (size_t offset = 0; offset < total; offset += segment) {
    const size_t s = offset < send_count ? std::min(segment, send_count - offset) : 0;
    const size_t r = offset < keep_count ? std::min(segment, keep_count - offset) : 0;
    const uint64_t *send_at = send + std::min(offset, send_count);
    const int rc = MPI_Sendrecv(send_at, int(s), MPI_UINT64_T, partner, kTag, scratch.data(),
                                int(r), MPI_UINT64_T, partner, kTag, comm, MPI_STATUS_IGNORE);
    if (rc != MPI_SUCCESS) return mpi_error(rc, "MPI_Sendrecv");
    min_merge(scratch.data(), r, keep + std::min(offset, keep_count));
  }
  return {};
}

// Extra ranks (>= base) hand their whole image to rank - base, which merges it.
std::string fold_extra_ranks(MPI_Comm comm, int rank, int ranks, int base, uint64_t *packed,
                             size_t pixels, PackedBuffer &scratch) {
  if (rank >= base) return swap_and_merge(comm, rank - base, packed, pixels, packed, 0, scratch);
  if (rank + base < ranks)
    return swap_and_merge(comm, rank + base, packed, 0, packed, pixels, scratch);
  return {};
}

std::string swap_rounds(MPI_Comm comm, int rank, int base, uint64_t *packed, size_t pixels,
                        PackedBuffer &scratch) {
  Range r{0, pixels};
  for (int bit = 1; bit < base; bit <<= 1) {
    const size_t mid = r.lo + r.size() / 2;
    const bool upper = (rank & bit) != 0;
    const Range keep = upper ? Range{mid, r.hi} : Range{r.lo, mid};
    const Range give = upper ? Range{r.lo, mid} : Range{mid, r.hi};
    const std::string error = swap_and_merge(comm, rank ^ bit, packed + give.lo, give.size(),
                                             packed + keep.lo, keep.size(), scratch);
    if (!error.empty()) return error;
    r = keep;
  }
  return {};
}

std::string gather_pieces(MPI_Comm comm, int rank, int ranks, int base, int root, uint64_t *packed,
                          size_t pixels) {
  std::vector<int> counts(size_t(ranks), 0), displacements(size_t(ranks), 0);
  for (int i = 0; i < base; ++i) {
    const Range r = owned_range(i, base, pixels);
    counts[size_t(i)] = int(r.size());
    displacements[size_t(i)] = int(r.lo);
  }
  const size_t own_count = size_t(counts[size_t(rank)]);
  const size_t own_first = size_t(displacements[size_t(rank)]);
  // Root's own piece already sits at its place in packed, hence MPI_IN_PLACE.
  const void *send = rank == root ? MPI_IN_PLACE : packed + own_first;
  const int rc = MPI_Gatherv(send, int(own_count), MPI_UINT64_T, packed, counts.data(),
                             displacements.data(), MPI_UINT64_T, root, comm);
  return mpi_error(rc, "MPI_Gatherv");
}

}  // namespace

std::string composite_binary_swap(MPI_Comm comm, Frame &frame, int root, MethodScratch &scratch) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const size_t pixels = frame.pixel_count();
  const int base = largest_power_of_two_at_most(ranks);
  uint64_t *packed = scratch.packed.data();
  pack_pixels(frame, 0, pixels, packed);

  std::string error = fold_extra_ranks(comm, rank, ranks, base, packed, pixels, scratch.received);
  if (error.empty() && rank < base)
    error = swap_rounds(comm, rank, base, packed, pixels, scratch.received);
  // A failed MPI call is fatal under MPI's default error handler; with MPI_ERRORS_RETURN we still
  // enter the gather so that no partner is left waiting.
  const std::string gather_error = gather_pieces(comm, rank, ranks, base, root, packed, pixels);
  if (error.empty()) error = gather_error;
  if (error.empty() && rank == root) unpack_pixels(packed, 0, pixels, frame);
  return error;
}

}  // namespace lantern
