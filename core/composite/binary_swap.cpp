// Hand-written binary swap (Ma et al. 1994), merging the frames in place.
//
// With p ranks, let q be the largest power of two <= p. Ranks q..p-1 first fold their whole image
// into rank r - q; then the q base ranks run log2(q) rounds, each halving the region it owns and
// swapping the other half with its partner (rank ^ bit); finally root gathers the q pieces
// straight into its frame. Each rank merges only its share, so the merge work is spread over all
// ranks, and no pixel is packed or unpacked outside the merge itself.
//
// Point-to-point messages use kDepthTag/kColourTag on comm; a caller that sends its own messages
// on the same communicator should give compositing a duplicate (MPI_Comm_dup).
#include <algorithm>
#include <array>
#include <vector>

#include "core/composite/composite_methods.h"
#include "core/composite/packed_pixel.h"

namespace lantern {
namespace {

constexpr int kDepthTag = 0x4c43;  // "LC"
constexpr int kColourTag = kDepthTag + 1;

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

// Sends the pixels `give` of frame to partner while receiving the partner's pixels for `keep` and
// merging them in, one scratch-sized segment at a time. The partner calls it with the ranges
// swapped, so both walk the same segments. Either range may be empty (folding).
std::string swap_and_merge(MPI_Comm comm, int partner, Frame &frame, Range give, Range keep,
                           MethodScratch &scratch) {
  const size_t segment = scratch.depth.size();
  const size_t total = std::max(give.size(), keep.size());
  for (size_t offset = 0; offset < total; offset += segment) {
    const size_t s = offset < give.size() ? std::min(segment, give.size() - offset) : 0;
    const size_t r = offset < keep.size() ? std::min(segment, keep.size() - offset) : 0;
    const size_t send_at = give.lo + std::min(offset, give.size());
    const size_t merge_at = keep.lo + std::min(offset, keep.size());
    std::array<MPI_Request, 4> requests;
    MPI_Irecv(scratch.depth.data(), int(r), MPI_FLOAT, partner, kDepthTag, comm, &requests[0]);
    MPI_Irecv(scratch.rgba.data(), int(4 * r), MPI_UINT8_T, partner, kColourTag, comm,
              &requests[1]);
    MPI_Isend(frame.depth.data() + send_at, int(s), MPI_FLOAT, partner, kDepthTag, comm,
              &requests[2]);
    MPI_Isend(frame.rgba.data() + 4 * send_at, int(4 * s), MPI_UINT8_T, partner, kColourTag, comm,
              &requests[3]);
    const int rc = MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
    if (rc != MPI_SUCCESS) return mpi_error(rc, "binary swap: MPI_Waitall");
    merge_pixels(scratch.depth.data(), scratch.rgba.data(), r, frame.depth.data() + merge_at,
                 frame.rgba.data() + 4 * merge_at);
  }
  return {};
}

// Extra ranks (>= base) hand their whole image to rank - base, which merges it.
std::string fold_extra_ranks(MPI_Comm comm, int rank, int ranks, int base, Frame &frame,
                             MethodScratch &scratch) {
  const Range all{0, frame.pixel_count()}, none{};
  if (rank >= base) return swap_and_merge(comm, rank - base, frame, all, none, scratch);
  if (rank + base < ranks) return swap_and_merge(comm, rank + base, frame, none, all, scratch);
  return {};
}

std::string swap_rounds(MPI_Comm comm, int rank, int base, Frame &frame, MethodScratch &scratch) {
  Range r{0, frame.pixel_count()};
  for (int bit = 1; bit < base; bit <<= 1) {
    const size_t mid = r.lo + r.size() / 2;
    const bool upper = (rank & bit) != 0;
    const Range keep = upper ? Range{mid, r.hi} : Range{r.lo, mid};
    const Range give = upper ? Range{r.lo, mid} : Range{mid, r.hi};
    const std::string error = swap_and_merge(comm, rank ^ bit, frame, give, keep, scratch);
    if (!error.empty()) return error;
    r = keep;
  }
  return {};
}

// Gathers the owned pieces into root's frame; root's own piece is already in place.
std::string gather_pieces(MPI_Comm comm, int rank, int ranks, int base, int root, Frame &frame) {
  std::vector<int> counts(size_t(ranks), 0), firsts(size_t(ranks), 0);
  for (int i = 0; i < base; ++i) {
    const Range r = owned_range(i, base, frame.pixel_count());
    counts[size_t(i)] = int(r.size());
    firsts[size_t(i)] = int(r.lo);
  }
  const int own_count = counts[size_t(rank)];
  const size_t own_first = size_t(firsts[size_t(rank)]);
  const bool is_root = rank == root;
  int rc =
      MPI_Gatherv(is_root ? MPI_IN_PLACE : frame.depth.data() + own_first, own_count, MPI_FLOAT,
                  frame.depth.data(), counts.data(), firsts.data(), MPI_FLOAT, root, comm);
  if (rc != MPI_SUCCESS) return mpi_error(rc, "binary swap: MPI_Gatherv (depth)");
  for (int i = 0; i < ranks; ++i) {
    counts[size_t(i)] *= 4;
    firsts[size_t(i)] *= 4;
  }
  rc = MPI_Gatherv(is_root ? MPI_IN_PLACE : frame.rgba.data() + 4 * own_first, 4 * own_count,
                   MPI_UINT8_T, frame.rgba.data(), counts.data(), firsts.data(), MPI_UINT8_T, root,
                   comm);
  return mpi_error(rc, "binary swap: MPI_Gatherv (colour)");
}

}  // namespace

std::string composite_binary_swap(MPI_Comm comm, Frame &frame, int root, MethodScratch &scratch) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const int base = largest_power_of_two_at_most(ranks);
  std::string error = fold_extra_ranks(comm, rank, ranks, base, frame, scratch);
  if (error.empty() && rank < base) error = swap_rounds(comm, rank, base, frame, scratch);
  // A failed MPI call is fatal under MPI's default error handler; with MPI_ERRORS_RETURN we still
  // enter the gather so that no partner is left waiting.
  const std::string gather_error = gather_pieces(comm, rank, ranks, base, root, frame);
  return error.empty() ? gather_error : error;
}

}  // namespace lantern
