#include "core/composite/active_pixel_exchange.h"

#include <algorithm>

#include "core/common/injected_fault.h"
#include "core/composite/composite_methods.h"

namespace lantern {
namespace {

// Each stream's share of a pool: at most what its whole range can take (R + 2 words), at least
// one minimal message.
size_t share_of(size_t pool, size_t streams, PixelRange range) {
  const size_t fair = std::max(kMinMessageWords, pool / std::max<size_t>(streams, 1));
  return std::min(fair, std::max(kMinMessageWords, range.size() + 2));
}

}  // namespace

void ActivePixelScratch::prepare(size_t chunk_pixels, int ranks) {
  const size_t words =
      std::max(std::min(chunk_pixels + 2, kActivePoolWords), size_t(ranks) * kMinMessageWords);
  if (send.size() < words) send.resize(words);
  if (receive.size() < words) receive.resize(words);
  pool_words = words;
}

Status exchange_active_pixels(MPI_Comm comm, int tag, size_t streams,
                              const std::vector<OutgoingRange> &outgoing,
                              const std::vector<IncomingRange> &incoming, ActiveFrame &frame,
                              ActivePixelScratch &scratch, CompositeTraffic *traffic) {
  struct Out {
    int to;
    RunLengthEncoder encoder;
    uint64_t *buffer;
    size_t capacity;
  };
  struct In {
    int from;
    RunLengthDecoder decoder;
    uint64_t *buffer;
    size_t capacity;
    bool finished = false;
    bool failed = false;  // a malformed message: the rest of the stream is received, not applied
  };
  std::vector<Out> outs;
  std::vector<In> ins;
  // Both ends of a stream size its messages from the same agreed numbers (see the header): a
  // root receiving from q - 1 ranks, each of which sends to it alone, must not have its senders
  // fill a whole pool each.
  size_t send_streams = 0, receive_streams = 0;
  for (const OutgoingRange &o : outgoing) send_streams += o.range.size() > 0;
  for (const IncomingRange &i : incoming) receive_streams += i.range.size() > 0;
  const size_t shares = std::max({streams, send_streams, receive_streams});
  const size_t pool = std::min({scratch.pool_words, scratch.send.size(), scratch.receive.size()});
  size_t send_at = 0, receive_at = 0;
  for (const OutgoingRange &o : outgoing) {
    if (o.range.size() == 0) continue;
    const size_t capacity = share_of(pool, shares, o.range);
    outs.push_back({o.to, RunLengthEncoder(o.range), scratch.send.data() + send_at, capacity});
    send_at += capacity;
  }
  for (const IncomingRange &i : incoming) {
    if (i.range.size() == 0) continue;
    const size_t capacity = share_of(pool, shares, i.range);
    ins.push_back(
        {i.from, RunLengthDecoder(i.range), scratch.receive.data() + receive_at, capacity});
    receive_at += capacity;
  }

  Status malformed;
  std::vector<MPI_Request> requests;
  std::vector<MPI_Status> statuses;
  std::vector<size_t> receiving;  // indices into ins of this step's receives
  for (;;) {
    requests.clear();
    receiving.clear();
    for (size_t k = 0; k < ins.size(); ++k) {
      if (ins[k].finished) continue;
      requests.emplace_back();
      MPI_Irecv(ins[k].buffer, int(ins[k].capacity), MPI_UINT64_T, ins[k].from, tag, comm,
                &requests.back());
      receiving.push_back(k);
    }
    for (Out &o : outs) {
      if (o.encoder.done()) continue;
      const double t0 = thread_cpu_ms();
      const size_t words = o.encoder.encode(frame, o.buffer, o.capacity);
      traffic->work_cpu_ms += thread_cpu_ms() - t0;
      requests.emplace_back();
      MPI_Isend(o.buffer, int(words), MPI_UINT64_T, o.to, tag, comm, &requests.back());
      traffic->bytes_sent += 8 * words;
      ++traffic->messages_sent;
    }
    if (requests.empty()) break;
    statuses.resize(requests.size());
    const int rc = MPI_Waitall(int(requests.size()), requests.data(), statuses.data());
    if (rc != MPI_SUCCESS) return mpi_error(rc, "compositing: active-pixel exchange");
    const double t0 = thread_cpu_ms();
    for (size_t r = 0; r < receiving.size(); ++r) {
      In &in = ins[receiving[r]];
      int words = 0;
      MPI_Get_count(&statuses[r], MPI_UINT64_T, &words);
      traffic->bytes_received += 8 * uint64_t(words);
      ++traffic->messages_received;
      const size_t length = size_t(std::max(words, 0));
      if (!in.failed) {
        Status decoded =
            take_injected_fault("active pixels: decode")
                ? Status(StatusCode::kInternal, "active pixels: decode (injected fault)")
                : in.decoder.decode(in.buffer, length, frame);
        if (decoded.ok()) {
          in.finished = in.decoder.done();
          continue;
        }
        in.failed = true;
        if (malformed.ok()) malformed = std::move(decoded);
      }
      // The sender still streams to its last message, which says so in its header.
      in.finished = length > 0 && (in.buffer[0] >> 63) != 0;
    }
    traffic->work_cpu_ms += thread_cpu_ms() - t0;
  }
  return malformed;
}

}  // namespace lantern
