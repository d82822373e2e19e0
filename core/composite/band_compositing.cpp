#include "core/composite/band_compositing.h"

#include <climits>
#include <new>
#include <vector>

#include "core/common/collective_status.h"
#include "core/composite/composite_methods.h"
#include "core/composite/pixel_exchange.h"

namespace lantern {

Status composite_to_row_bands(MPI_Comm comm, Frame &frame, int multiple, RowBand *owned,
                              CompositeStats *stats_out) {
  const double start = MPI_Wtime();
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  CompositeStats discarded;
  CompositeStats &stats = stats_out ? *stats_out : discarded;
  stats = CompositeStats();
  stats.ranks = ranks;
  stats.pixels = frame.pixel_count();
  *owned = row_band(frame.height, ranks, rank, multiple);
  const bool consistent =
      frame.width >= 0 && frame.height >= 0 && multiple > 0 && frame.height % multiple == 0 &&
      frame.rgba.size() == 4 * frame.pixel_count() && frame.depth.size() == frame.pixel_count() &&
      frame.pixel_count() <= size_t(INT_MAX / 4);
  if (ranks == 1) {
    stats.method = "none";
    stats.milliseconds = (MPI_Wtime() - start) * 1e3;
    if (!consistent) return {StatusCode::kMpi, "composite_to_row_bands: inconsistent frame"};
    return {};
  }
  stats.method = "direct_send_bands";
  // Kept between calls (one chunk), as composite_frames keeps its own.
  thread_local MethodScratch scratch;
  bool allocated = true;
  if (consistent) {
    try {
      prepare_scratch(CompositeMethod::kDirectSend, frame.pixel_count(), ranks,
                      kDefaultCompositeChunkPixels, scratch);
    } catch (const std::bad_alloc &) {
      allocated = false;
    }
  }
  // Sizes as (x, -x) pairs under one MPI_MIN: equal everywhere iff min == max.
  long long agreement[] = {frame.width, -frame.width, frame.height, -frame.height,
                           multiple,    -multiple,    consistent,   allocated};
  MPI_Allreduce(MPI_IN_PLACE, agreement, 8, MPI_LONG_LONG, MPI_MIN, comm);
  Status status;
  if (agreement[6] == 0)
    status = {StatusCode::kMpi,
              "composite_to_row_bands: a rank has an inconsistent frame, more than INT_MAX / 4 "
              "pixels, or a height that is not a multiple of " +
                  std::to_string(multiple)};
  else if (agreement[0] != -agreement[1] || agreement[2] != -agreement[3] ||
           agreement[4] != -agreement[5])
    status = {StatusCode::kMpi, "composite_to_row_bands: frame sizes differ between ranks"};
  else if (agreement[7] == 0)
    status = {StatusCode::kMpi, "composite_to_row_bands: a rank could not allocate scratch memory"};
  if (!status.ok()) {
    stats.milliseconds = (MPI_Wtime() - start) * 1e3;
    return status;
  }

  const size_t width = size_t(frame.width);
  std::vector<PixelRange> blocks(static_cast<size_t>(ranks));
  for (int k = 0; k < ranks; ++k) {
    const RowBand b = row_band(frame.height, ranks, k, multiple);
    blocks[size_t(k)] = {size_t(b.y0) * width, size_t(b.y1) * width};
  }
  // Direct send over the bands: in step s every rank sends band (rank + s) to its owner and
  // merges the copy of its own band from rank (rank - s).
  for (int step = 1; step < ranks && status.ok(); ++step) {
    const int to = (rank + step) % ranks, from = (rank - step + ranks) % ranks;
    status = exchange_and_merge(comm, to, blocks[size_t(to)], from, blocks[size_t(rank)], frame,
                                scratch);
  }
  stats.milliseconds = (MPI_Wtime() - start) * 1e3;
  return agree_on_status(comm, status);
}

}  // namespace lantern
