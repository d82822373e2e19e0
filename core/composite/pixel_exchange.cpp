#include "core/composite/pixel_exchange.h"

#include <algorithm>
#include <array>

#include "core/composite/packed_pixel.h"

namespace lantern {
namespace {

constexpr int kDepthTag = 0x4c43;  // "LC"
constexpr int kColorTag = kDepthTag + 1;
constexpr int kGatherDepthTag = kDepthTag + 2;
constexpr int kGatherColorTag = kDepthTag + 3;

size_t segments_of(size_t count, size_t segment) {
  return (count + segment - 1) / segment;
}

}  // namespace

Status exchange_and_merge(MPI_Comm comm, int send_to, PixelRange give, int recv_from,
                          PixelRange keep, Frame &frame, MethodScratch &scratch,
                          CompositeTraffic *traffic) {
  const size_t segment = scratch.depth.size();
  // Segment k of give and segment k of keep travel together. Every rank waits at step k only for
  // partners' step k, which they reach because both sides cut the same range the same way: no
  // deadlock, and (unlike posting every send at once) no flood of unexpected messages when the
  // segments are small.
  const size_t steps =
      std::max(segments_of(give.size(), segment), segments_of(keep.size(), segment));
  for (size_t k = 0; k < steps; ++k) {
    std::array<MPI_Request, 4> requests;
    int posted = 0;
    const size_t send_first = give.lo + k * segment, recv_first = keep.lo + k * segment;
    const int send_count = send_first < give.hi ? int(std::min(segment, give.hi - send_first)) : 0;
    const int recv_count = recv_first < keep.hi ? int(std::min(segment, keep.hi - recv_first)) : 0;
    if (recv_count > 0) {
      MPI_Irecv(scratch.depth.data(), recv_count, MPI_FLOAT, recv_from, kDepthTag, comm,
                &requests[posted++]);
      MPI_Irecv(scratch.rgba.data(), 4 * recv_count, MPI_UINT8_T, recv_from, kColorTag, comm,
                &requests[posted++]);
    }
    if (send_count > 0) {
      MPI_Isend(frame.depth.data() + send_first, send_count, MPI_FLOAT, send_to, kDepthTag, comm,
                &requests[posted++]);
      MPI_Isend(frame.rgba.data() + 4 * send_first, 4 * send_count, MPI_UINT8_T, send_to, kColorTag,
                comm, &requests[posted++]);
    }
    const int rc = MPI_Waitall(posted, requests.data(), MPI_STATUSES_IGNORE);
    if (rc != MPI_SUCCESS) return mpi_error(rc, "compositing: exchange");
    // A pixel is 8 bytes: its depth and its colour travel as two messages.
    traffic->bytes_sent += 8 * uint64_t(send_count);
    traffic->messages_sent += send_count > 0 ? 2 : 0;
    traffic->bytes_received += 8 * uint64_t(recv_count);
    traffic->messages_received += recv_count > 0 ? 2 : 0;
    const double t0 = thread_cpu_ms();
    merge_pixels(scratch.depth.data(), scratch.rgba.data(), size_t(recv_count),
                 frame.depth.data() + recv_first, frame.rgba.data() + 4 * recv_first);
    traffic->work_cpu_ms += thread_cpu_ms() - t0;
  }
  return {};
}

Status gather_ranges(MPI_Comm comm, int root, const std::vector<PixelRange> &owned, Frame &frame,
                     CompositeTraffic *traffic) {
  // Point-to-point rather than two MPI_Gatherv (depth, color): root receives every piece of both
  // arrays under one MPI_Waitall, one synchronisation instead of two, which matters when ranks
  // share cores. Open MPI's gatherv is linear at these sizes anyway.
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::vector<MPI_Request> requests;
  const auto post = [&](bool receive, int peer, PixelRange r) {
    if (r.size() == 0) return;
    float *depth = frame.depth.data() + r.lo;
    uint8_t *rgba = frame.rgba.data() + 4 * r.lo;
    const int count = int(r.size());
    (receive ? traffic->bytes_received : traffic->bytes_sent) += 8 * uint64_t(count);
    (receive ? traffic->messages_received : traffic->messages_sent) += 2;
    requests.emplace_back();
    if (receive) {
      MPI_Irecv(depth, count, MPI_FLOAT, peer, kGatherDepthTag, comm, &requests.back());
    } else {
      MPI_Isend(depth, count, MPI_FLOAT, peer, kGatherDepthTag, comm, &requests.back());
    }
    requests.emplace_back();
    if (receive) {
      MPI_Irecv(rgba, 4 * count, MPI_UINT8_T, peer, kGatherColorTag, comm, &requests.back());
    } else {
      MPI_Isend(rgba, 4 * count, MPI_UINT8_T, peer, kGatherColorTag, comm, &requests.back());
    }
  };
  if (rank == root) {
    for (size_t i = 0; i < owned.size(); ++i)
      if (int(i) != root) post(true, int(i), owned[i]);
  } else {
    post(false, root, owned[size_t(rank)]);
  }
  const int rc = MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  return mpi_error(rc, "compositing: gather to root");
}

}  // namespace lantern
