#include "core/composite/depth_compositor.h"

#include <climits>
#include <new>

#include "core/common/collective_status.h"
#include "core/composite/active_pixel_compositing.h"
#include "core/composite/composite_methods.h"
#include "core/composite/rank_agreement.h"

namespace lantern {
namespace {

// kAuto's sample for choosing between dense and active pixels: every 16th row (a sphere a few
// pixels across is seen by some sampled row; the estimate only steers the choice, never the image).
constexpr int kSampleRowStep = 16;

bool frame_is_consistent(const Frame &frame) {
  return frame.width >= 0 && frame.height >= 0 && frame.rgba.size() == 4 * frame.pixel_count() &&
         frame.depth.size() == frame.pixel_count();
}

double elapsed_ms(double start) {
  return (MPI_Wtime() - start) * 1e3;
}

Status failed(const std::string &what) {
  return {StatusCode::kMpi, "composite: " + what};
}

// kAuto's dense method: one MPI_Reduce of the whole frame or the dense binary swap, whichever
// the model prices lower (the reduce on a tie).
struct DenseChoice {
  CompositeMethod method = CompositeMethod::kReduce64;
  CostEstimate estimate;
};

DenseChoice auto_dense(int ranks, size_t pixels, const CompositeCostModel &model) {
  DenseChoice d{CompositeMethod::kReduce64, estimate_reduce64(ranks, pixels, model)};
  const CostEstimate swap = estimate_dense_binary_swap(ranks, pixels, model);
  if (swap.seconds < d.estimate.seconds) d = {CompositeMethod::kBinarySwap, swap};
  return d;
}

// Whether the methods that may run need the active-pixel scan and scratch, and the dense scratch.
struct Needs {
  bool active = false;
  bool dense = false;
};

Needs needs_of(const CompositeOptions &o, int ranks, size_t pixels,
               const CompositeCostModel &model) {
  if (o.method == CompositeMethod::kActivePixels) return {true, false};
  if (o.method != CompositeMethod::kAuto) return {false, true};
  // kAuto: the dense method against active pixels at their best (nothing drawn) and at their
  // worst (everything drawn): only where the dense method beats active pixels at their best is
  // the scan skipped; only where it beats them at their worst is its scratch kept.
  const double dense = auto_dense(ranks, pixels, model).estimate.seconds;
  CostEstimate best, worst;
  cheapest_schedule(ranks, pixels, 0, true, model, &best);
  cheapest_schedule(ranks, pixels, pixels, true, model, &worst);
  return {best.seconds < dense, worst.seconds >= dense};
}

}  // namespace

const char *to_string(CompositeMethod method) {
  switch (method) {
    case CompositeMethod::kAuto:
      return "auto";
    case CompositeMethod::kReduce64:
      return "reduce64";
    case CompositeMethod::kReduceScatter:
      return "reduce_scatter";
    case CompositeMethod::kBinarySwap:
      return "binary_swap";
    case CompositeMethod::kDirectSend:
      return "direct_send";
    case CompositeMethod::kActivePixels:
      return "active_pixels";
  }
  return "unknown";
}

bool parse_composite_method(const std::string &name, CompositeMethod *method) {
  for (const CompositeMethod m : {CompositeMethod::kAuto, CompositeMethod::kReduce64,
                                  CompositeMethod::kReduceScatter, CompositeMethod::kBinarySwap,
                                  CompositeMethod::kDirectSend, CompositeMethod::kActivePixels}) {
    if (name == to_string(m)) {
      *method = m;
      return true;
    }
  }
  return false;
}

Status composite_frames(MPI_Comm comm, Frame &frame, int root, const CompositeOptions &options,
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
  const bool local_ok = frame_is_consistent(frame) && stats.pixels <= size_t(INT_MAX / 4) &&
                        root >= 0 && root < ranks;
  if (ranks == 1) {
    // Nothing to merge: the frame already is the image. No copy, no MPI call.
    stats.method = "none";
    stats.milliseconds = elapsed_ms(start);
    if (!local_ok) return {StatusCode::kMpi, "composite: inconsistent frame or root != 0"};
    return {};
  }

  const size_t chunk =
      options.chunk_pixels == 0 ? kDefaultCompositeChunkPixels : options.chunk_pixels;
  const CompositeCostModel model = options.model ? *options.model : default_cost_model();
  const Needs needs = local_ok ? needs_of(options, ranks, stats.pixels, model) : Needs{};
  // Where kAuto may run either, a sample of the rows decides first, so that a frame composited
  // densely is never scanned whole (the scan costs about as much as a dense merge of half the
  // frame); the full scan follows only when active pixels win on the sample. Agreed as a flag, so
  // every rank takes the same path.
  const bool sampled = options.method == CompositeMethod::kAuto && needs.active && needs.dense &&
                       frame.height >= 4 * kSampleRowStep;
  ActiveScan scan;
  if (needs.active) {
    const double t0 = thread_cpu_ms();
    scan = sampled ? sample_active_pixels(frame, kSampleRowStep) : scan_active_pixels(frame);
    stats.traffic.work_cpu_ms += thread_cpu_ms() - t0;
  }
  const DenseChoice auto_choice = auto_dense(ranks, stats.pixels, model);
  const CompositeMethod dense =
      options.method == CompositeMethod::kAuto ? auto_choice.method : options.method;
  // The dense scratch is kept between frames so steady-state frames neither allocate nor
  // page-fault; bounded by about two chunks whatever the frame size. The active-pixel pool is
  // a local, freed at the end of each call, its pages lazily kept for the next (kActivePoolWords).
  // thread_local: concurrent callers never share it.
  thread_local MethodScratch scratch;
  ActivePixelScratch active_scratch;  // this call's only
  bool allocated = true;
  try {
    if (needs.active) active_scratch.prepare(chunk, ranks);
    if (needs.dense) prepare_scratch(dense, stats.pixels, ranks, chunk, scratch);
  } catch (const std::bad_alloc &) {
    allocated = false;  // reported collectively below, so no rank enters the method alone
  }

  RankAgreement agree;
  const size_t width = agree.equal(frame.width), height = agree.equal(frame.height);
  const size_t root_at = agree.equal(root);
  const size_t setup =
      agree.equal(static_cast<long long>(options.method) * 1000003 + static_cast<long long>(chunk));
  const size_t model_at = agree.equal(cost_model_fingerprint(model, options.schedule));
  const size_t sampled_at = agree.equal(sampled);
  const ScanAgreement scans(agree, scan);
  const size_t ok_at = agree.all(local_ok), allocated_at = agree.all(allocated);
  Status status = agree.reduce(comm);
  if (status.ok() && !agree.holds(ok_at))
    status = failed(
        "a rank has an inconsistent frame, more than INT_MAX / 4 pixels, or a root outside [0, " +
        std::to_string(ranks) + ")");
  if (status.ok() && (!agree.agreed(width) || !agree.agreed(height)))
    status = failed("frame sizes differ between ranks");
  if (status.ok() && !agree.agreed(root_at)) status = failed("ranks passed different roots");
  if (status.ok() && !agree.agreed(setup))
    status = failed("ranks passed different methods or chunk sizes");
  if (status.ok() && !agree.agreed(model_at))
    status = failed("ranks passed different cost models or schedules");
  if (status.ok() && !agree.agreed(sampled_at))
    status = failed("ranks disagree on sampling the frame");
  if (status.ok() && !agree.holds(allocated_at))
    status = failed("a rank could not allocate scratch memory");

  // What runs: a pure function of agreed values, so the same on every rank.
  CompositingSchedule schedule;
  CostEstimate estimate;
  bool active = needs.active;
  uint64_t empty_key = 0;
  if (status.ok() && active) {
    size_t most = scans.busiest(agree, stats.pixels);
    empty_key = scans.empty_key(agree);
    if (sampled) {
      CostEstimate guess;
      cheapest_schedule(ranks, stats.pixels, most, true, model, &guess);
      if (auto_choice.estimate.seconds <= guess.seconds) {
        active = false;  // dense, decided on the sample
      } else {
        // Active pixels: the whole frame scanned and agreed on after all.
        const double t0 = thread_cpu_ms();
        scan = scan_active_pixels(frame);
        stats.traffic.work_cpu_ms += thread_cpu_ms() - t0;
        RankAgreement full;
        const ScanAgreement full_scans(full, scan);
        status = full.reduce(comm);
        most = full_scans.busiest(full, stats.pixels);
        empty_key = full_scans.empty_key(full);
      }
    }
    if (!status.ok() || !active) {
      estimate = auto_choice.estimate;
    } else if (!options.schedule) {
      schedule = cheapest_schedule(ranks, stats.pixels, most, true, model, &estimate);
    } else {
      schedule = *options.schedule;
      schedule.ranks = ranks;
      estimate = estimate_active_pixels(schedule, stats.pixels, most, true, model);
      if (!schedule.valid())
        status = failed("schedule " + schedule.name() + " does not fit " + std::to_string(ranks) +
                        " ranks");
    }
    if (active && needs.dense && auto_choice.estimate.seconds <= estimate.seconds)
      active = false, estimate = auto_choice.estimate;  // kAuto: dense is cheaper
  } else if (status.ok() && options.method == CompositeMethod::kAuto) {
    estimate = auto_choice.estimate;
  } else if (status.ok() && dense == CompositeMethod::kReduce64) {
    estimate = estimate_reduce64(ranks, stats.pixels, model);
  } else if (status.ok() && dense == CompositeMethod::kBinarySwap) {
    estimate = estimate_dense_binary_swap(ranks, stats.pixels, model);
  }
  stats.model_ms = estimate.seconds * 1e3;
  if (active) {
    stats.method = to_string(CompositeMethod::kActivePixels);
    stats.schedule = schedule.name();
    // A rank whose own maximum is below everyone's has no empty pixel: all of it is active.
    const bool own_empty = scan.max_key == empty_key;
    stats.active_pixels = own_empty ? scan.active : stats.pixels;
    if (status.ok() && stats.pixels > 0) {
      ActiveFrame active_frame{&frame, empty_pixel(empty_key),
                               own_empty ? scan.rect : ActiveRect{0, 0, frame.width, frame.height}};
      ActivePixelPlan plan{schedule, equal_blocks(stats.pixels, schedule.base()), root, {}};
      status = run_active_pixel_plan(comm, plan, active_frame, active_scratch, &stats.traffic);
    }
  } else {
    stats.method = to_string(dense);
    // kAuto chose it: the stats name it as the schedule the model picked.
    if (options.method == CompositeMethod::kAuto)
      stats.schedule = std::string("dense ") + to_string(dense);
    if (status.ok() && stats.pixels > 0)
      status = run_method(dense, comm, frame, root, chunk, scratch, &stats.traffic);
  }
  // A failure only some ranks saw (a message one rank could not decode) is every rank's: the
  // callers go on to collective steps (the image's write) only when compositing succeeded.
  status = agree_on_status(comm, status);
  stats.milliseconds = elapsed_ms(start);
  return status;
}

}  // namespace lantern
