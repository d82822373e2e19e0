#include "core/composite/depth_compositor.h"

#include <climits>
#include <new>

#include "core/composite/composite_methods.h"
#include "core/composite/method_table.h"

namespace lantern {
namespace {

bool frame_is_consistent(const Frame &frame) {
  return frame.width >= 0 && frame.height >= 0 && frame.rgba.size() == 4 * frame.pixel_count() &&
         frame.depth.size() == frame.pixel_count();
}

// What every rank must agree on, laid out for one MPI_MIN: x and -x give both min and max.
struct Agreement {
  enum { kWidth, kHeight, kRoot, kMethod, kChunk, kCount };
  long long value[2 * kCount + 2];  // pairs (x, -x), then local_ok, allocated

  // OK, or kMpi: the ranks cannot run the collective together.
  Status check(int ranks) const {
    const auto agreed = [&](int k) { return value[2 * k] == -value[2 * k + 1]; };
    const auto failed = [](std::string what) {
      return Status(StatusCode::kMpi, "composite: " + what);
    };
    if (value[2 * kCount] == 0)
      return failed(
          "a rank has an inconsistent frame, more than INT_MAX / 4 pixels, or a root outside [0, " +
          std::to_string(ranks) + ")");
    if (!agreed(kWidth) || !agreed(kHeight)) return failed("frame sizes differ between ranks");
    if (!agreed(kRoot)) return failed("ranks passed different roots");
    if (!agreed(kMethod) || !agreed(kChunk))
      return failed("ranks passed different methods or chunk sizes");
    if (value[2 * kCount + 1] == 0) return failed("a rank could not allocate scratch memory");
    return {};
  }
};

double elapsed_ms(double start) {
  return (MPI_Wtime() - start) * 1e3;
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
  }
  return "unknown";
}

bool parse_composite_method(const std::string &name, CompositeMethod *method) {
  for (const CompositeMethod m :
       {CompositeMethod::kAuto, CompositeMethod::kReduce64, CompositeMethod::kReduceScatter,
        CompositeMethod::kBinarySwap, CompositeMethod::kDirectSend}) {
    if (name == to_string(m)) {
      *method = m;
      return true;
    }
  }
  return false;
}

Status composite_frames(MPI_Comm comm, Frame &frame, int root, CompositeMethod method,
                        size_t chunk_pixels, CompositeStats *stats_out) {
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

  const size_t chunk = chunk_pixels == 0 ? kDefaultCompositeChunkPixels : chunk_pixels;
  const CompositeMethod chosen =
      method == CompositeMethod::kAuto ? auto_composite_method(ranks, stats.pixels) : method;
  // Kept between frames so steady-state frames neither allocate nor page-fault; bounded by about
  // two chunks whatever the frame size. thread_local: concurrent callers never share it.
  thread_local MethodScratch scratch;
  bool allocated = true;
  if (local_ok) {
    try {
      prepare_scratch(chosen, stats.pixels, ranks, chunk, scratch);
    } catch (const std::bad_alloc &) {
      allocated = false;  // reported collectively below, so no rank enters the method alone
    }
  }
  const long long fields[] = {frame.width, frame.height, root, static_cast<long long>(chosen),
                              static_cast<long long>(chunk)};
  Agreement agreement{};
  for (int k = 0; k < Agreement::kCount; ++k) {
    agreement.value[2 * k] = fields[k];
    agreement.value[2 * k + 1] = -fields[k];
  }
  agreement.value[2 * Agreement::kCount] = local_ok;
  agreement.value[2 * Agreement::kCount + 1] = allocated;
  MPI_Allreduce(MPI_IN_PLACE, agreement.value, 2 * Agreement::kCount + 2, MPI_LONG_LONG, MPI_MIN,
                comm);

  stats.method = to_string(chosen);
  Status status = agreement.check(ranks);
  if (status.ok() && stats.pixels > 0)
    status = run_method(chosen, comm, frame, root, chunk, scratch);
  stats.milliseconds = elapsed_ms(start);
  return status;
}

}  // namespace lantern
