// Hand-written binary swap (Ma et al. 1994), merging the frames in place.
//
// With p ranks, let q be the largest power of two <= p. Ranks q..p-1 first fold their whole image
// into rank r - q; then the q base ranks run log2(q) rounds, each halving the region it owns and
// swapping the other half with its partner (rank ^ bit); finally root gathers the q pieces
// straight into its frame. Each rank merges only its share, so the merge work is spread over the
// base ranks, and no pixel is packed or unpacked outside the merge itself.
#include <vector>

#include "core/composite/composite_methods.h"
#include "core/composite/pixel_exchange.h"

namespace lantern {
namespace {

int largest_power_of_two_at_most(int n) {
  int q = 1;
  while (q * 2 <= n) q *= 2;
  return q;
}

// The pixels base rank `index` owns after every swap round among `base` ranks.
PixelRange owned_range(int index, int base, size_t pixels) {
  PixelRange r{0, pixels};
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

// Extra ranks (>= base) hand their whole image to rank - base, which merges it.
Status fold_extra_ranks(MPI_Comm comm, int rank, int ranks, int base, Frame &frame,
                        MethodScratch &scratch, CompositeTraffic *traffic) {
  const PixelRange all{0, frame.pixel_count()}, none{};
  if (rank >= base)
    return exchange_and_merge(comm, rank - base, all, rank, none, frame, scratch, traffic);
  if (rank + base < ranks)
    return exchange_and_merge(comm, rank, none, rank + base, all, frame, scratch, traffic);
  return {};
}

Status swap_rounds(MPI_Comm comm, int rank, int base, Frame &frame, MethodScratch &scratch,
                   CompositeTraffic *traffic) {
  PixelRange r{0, frame.pixel_count()};
  for (int bit = 1; bit < base; bit <<= 1) {
    const size_t mid = r.lo + r.size() / 2;
    const bool upper = (rank & bit) != 0;
    const PixelRange keep = upper ? PixelRange{mid, r.hi} : PixelRange{r.lo, mid};
    const PixelRange give = upper ? PixelRange{r.lo, mid} : PixelRange{mid, r.hi};
    const int partner = rank ^ bit;
    if (Status s = exchange_and_merge(comm, partner, give, partner, keep, frame, scratch, traffic);
        !s.ok())
      return s;
    r = keep;
  }
  return {};
}

}  // namespace

Status composite_binary_swap(MPI_Comm comm, Frame &frame, int root, MethodScratch &scratch,
                             CompositeTraffic *traffic) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const int base = largest_power_of_two_at_most(ranks);
  Status error = fold_extra_ranks(comm, rank, ranks, base, frame, scratch, traffic);
  if (error.ok() && rank < base) error = swap_rounds(comm, rank, base, frame, scratch, traffic);
  std::vector<PixelRange> owned(static_cast<size_t>(ranks));  // extra ranks own nothing
  for (int i = 0; i < base; ++i) owned[size_t(i)] = owned_range(i, base, frame.pixel_count());
  // A failed MPI call is fatal under MPI's default error handler; with MPI_ERRORS_RETURN we still
  // enter the gather so that no rank is left waiting in it.
  Status gather_error = gather_ranges(comm, root, owned, frame, traffic);
  return error.ok() ? gather_error : error;
}

}  // namespace lantern
