#include "core/composite/band_compositing.h"

#include <climits>
#include <new>
#include <vector>

#include "core/common/collective_status.h"
#include "core/composite/active_pixel_compositing.h"
#include "core/composite/composite_methods.h"
#include "core/composite/pixel_exchange.h"
#include "core/composite/rank_agreement.h"

namespace lantern {
namespace {

// Every rank's band as a pixel range.
std::vector<PixelRange> band_ranges(int width, int height, int ranks, int multiple) {
  std::vector<PixelRange> bands(static_cast<size_t>(ranks));
  for (int k = 0; k < ranks; ++k) {
    const RowBand b = row_band(height, ranks, k, multiple);
    bands[size_t(k)] = {size_t(b.y0) * size_t(width), size_t(b.y1) * size_t(width)};
  }
  return bands;
}

// Group g's block: the bands of its ranks (consecutive, so contiguous).
std::vector<PixelRange> group_blocks(const CompositingSchedule &s,
                                     const std::vector<PixelRange> &bands) {
  std::vector<PixelRange> blocks(static_cast<size_t>(s.base()));
  for (int g = 0; g < s.base(); ++g) {
    const int last = s.extra_rank(g) >= 0 ? s.extra_rank(g) : s.base_rank(g);
    blocks[size_t(g)] = {bands[size_t(s.base_rank(g))].lo, bands[size_t(last)].hi};
  }
  return blocks;
}

// Direct send over the bands: in step s every rank sends band (rank + s) to its owner and merges
// the copy of its own band from rank (rank - s).
Status direct_send_bands(MPI_Comm comm, Frame &frame, const std::vector<PixelRange> &bands,
                         MethodScratch &scratch, CompositeTraffic *traffic) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  Status status;
  for (int step = 1; step < ranks && status.ok(); ++step) {
    const int to = (rank + step) % ranks, from = (rank - step + ranks) % ranks;
    status = exchange_and_merge(comm, to, bands[size_t(to)], from, bands[size_t(rank)], frame,
                                scratch, traffic);
  }
  return status;
}

}  // namespace

Status composite_to_row_bands(MPI_Comm comm, Frame &frame, int multiple, RowBand *owned,
                              const CompositeOptions &options, CompositeStats *stats_out) {
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
  const bool dense = options.method == CompositeMethod::kDirectSend;
  if (!dense && options.method != CompositeMethod::kAuto &&
      options.method != CompositeMethod::kActivePixels)
    return {StatusCode::kInvalidArgument, std::string("composite_to_row_bands: method ") +
                                              to_string(options.method) +
                                              " cannot end in row bands"};
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
  stats.method = dense ? "direct_send_bands" : "active_pixels_bands";
  const size_t chunk =
      options.chunk_pixels == 0 ? kDefaultCompositeChunkPixels : options.chunk_pixels;
  const CompositeCostModel model = options.model ? *options.model : default_cost_model();
  ActiveScan scan;
  if (consistent && !dense) {
    const double t0 = thread_cpu_ms();
    scan = scan_active_pixels(frame);
    stats.traffic.work_cpu_ms += thread_cpu_ms() - t0;
  }
  // The dense scratch is kept between calls (about two chunks), as composite_frames keeps its
  // own; the active-pixel pool is a local, freed at the end of each call (kActivePoolWords).
  thread_local MethodScratch scratch;
  ActivePixelScratch active_scratch;  // this call's only
  bool allocated = true;
  if (consistent) {
    try {
      if (dense) {
        prepare_scratch(CompositeMethod::kDirectSend, frame.pixel_count(), ranks, chunk, scratch);
      } else {
        active_scratch.prepare(chunk, ranks);
      }
    } catch (const std::bad_alloc &) {
      allocated = false;
    }
  }
  RankAgreement agree;
  const size_t width = agree.equal(frame.width), height = agree.equal(frame.height);
  const size_t multiple_at = agree.equal(multiple);
  const size_t setup =
      agree.equal(static_cast<long long>(options.method) * 1000003 + static_cast<long long>(chunk));
  const size_t model_at = agree.equal(cost_model_fingerprint(model, options.schedule));
  const ScanAgreement scans(agree, scan);
  const size_t ok_at = agree.all(consistent), allocated_at = agree.all(allocated);
  Status status = agree.reduce(comm);
  if (status.ok() && !agree.holds(ok_at))
    status = {StatusCode::kMpi,
              "composite_to_row_bands: a rank has an inconsistent frame, more than INT_MAX / 4 "
              "pixels, or a height that is not a multiple of " +
                  std::to_string(multiple)};
  else if (status.ok() &&
           (!agree.agreed(width) || !agree.agreed(height) || !agree.agreed(multiple_at)))
    status = {StatusCode::kMpi, "composite_to_row_bands: frame sizes differ between ranks"};
  else if (status.ok() && (!agree.agreed(setup) || !agree.agreed(model_at)))
    status = {StatusCode::kMpi,
              "composite_to_row_bands: ranks passed different methods, chunks or cost models"};
  else if (status.ok() && !agree.holds(allocated_at))
    status = {StatusCode::kMpi, "composite_to_row_bands: a rank could not allocate scratch memory"};
  if (!status.ok()) {
    stats.milliseconds = (MPI_Wtime() - start) * 1e3;
    return status;
  }

  const std::vector<PixelRange> bands = band_ranges(frame.width, frame.height, ranks, multiple);
  if (dense) {
    status = direct_send_bands(comm, frame, bands, scratch, &stats.traffic);
  } else {
    const size_t most = scans.busiest(agree, stats.pixels);
    CostEstimate estimate;
    CompositingSchedule schedule;
    if (!options.schedule) {
      schedule = cheapest_schedule(ranks, stats.pixels, most, false, model, &estimate);
    } else {
      schedule = *options.schedule;
      schedule.ranks = ranks;
      estimate = estimate_active_pixels(schedule, stats.pixels, most, false, model);
    }
    stats.schedule = schedule.name();
    stats.model_ms = estimate.seconds * 1e3;
    const uint64_t empty_key = scans.empty_key(agree);
    const bool own_empty = scan.max_key == empty_key;
    stats.active_pixels = own_empty ? scan.active : stats.pixels;
    if (!schedule.valid() || schedule.tree) {
      status = {StatusCode::kMpi,
                "composite_to_row_bands: schedule " + schedule.name() +
                    (schedule.tree ? " cannot end in row bands"
                                   : " does not fit " + std::to_string(ranks) + " ranks")};
    } else if (stats.pixels > 0) {
      ActiveFrame active_frame{&frame, empty_pixel(empty_key),
                               own_empty ? scan.rect : ActiveRect{0, 0, frame.width, frame.height}};
      const ActivePixelPlan plan{schedule, group_blocks(schedule, bands), 0, bands};
      status = run_active_pixel_plan(comm, plan, active_frame, active_scratch, &stats.traffic);
    }
  }
  stats.milliseconds = (MPI_Wtime() - start) * 1e3;
  return agree_on_status(comm, status);
}

}  // namespace lantern
