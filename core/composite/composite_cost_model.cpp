#include "core/composite/composite_cost_model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

#include "core/composite/active_pixels.h"
#include "core/composite/composite_methods.h"
#include "core/composite/packed_pixel.h"
#include "core/composite/run_length_pixels.h"

namespace lantern {
namespace {

constexpr double kBytesPerPixel = 8.0;  // a packed key: depth bits and RGBA8
constexpr int kPingTag = 0x4c60;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Half the shortest round trip of `bytes`-byte messages between rank 0 and `peer` (on rank 0; the
// peer echoes). `runs` timed after `warmup`.
Status ping_pong(MPI_Comm comm, int rank, int peer_rank, std::vector<char> &buffer, int warmup,
                 int runs, double *seconds) {
  std::vector<double> trips;
  const int count = int(buffer.size());
  for (int r = 0; r < warmup + runs; ++r) {
    const double t0 = MPI_Wtime();
    int rc;
    if (rank == 0) {
      rc = MPI_Send(buffer.data(), count, MPI_CHAR, peer_rank, kPingTag, comm);
      if (rc == MPI_SUCCESS)
        rc = MPI_Recv(buffer.data(), count, MPI_CHAR, peer_rank, kPingTag, comm, MPI_STATUS_IGNORE);
    } else {
      rc = MPI_Recv(buffer.data(), count, MPI_CHAR, 0, kPingTag, comm, MPI_STATUS_IGNORE);
      if (rc == MPI_SUCCESS) rc = MPI_Send(buffer.data(), count, MPI_CHAR, 0, kPingTag, comm);
    }
    if (rc != MPI_SUCCESS) return mpi_error(rc, "measuring compositing's cost model");
    if (r >= warmup) trips.push_back(MPI_Wtime() - t0);
  }
  // The shortest: on shared cores most round trips also hold a wait for a core (other processes'
  // turns), which is the machine's load, not the transport's cost.
  *seconds = *std::min_element(trips.begin(), trips.end()) / 2;
  return {};
}

// A synthetic frame for timing the CPU work: half its pixels drawn, in 16-pixel squares (runs of
// 16 along a row), `phase` shifting the squares so that two frames overlap in half their drawn
// pixels, depths varying so that merges go both ways.
Frame timing_frame(int width, int height, int phase) {
  Frame f(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = f.index(x, y);
      const bool drawn = ((x / 16 + (y + phase) / 16) % 2) == 0;
      f.depth[i] = drawn ? 0.25f + float((x + 3 * y + 7 * phase) % 509) / 1024.0f : 1.0f;
      for (int c = 0; c < 4; ++c) f.rgba[4 * i + size_t(c)] = drawn ? uint8_t(60 + phase + c) : 0;
    }
  return f;
}

// The CPU figures of the model, per pixel, on this thread: medians over `runs` after a warm-up.
void measure_cpu_costs(CompositeCostModel *model) {
  constexpr int kWidth = 512, kHeight = 512, kRuns = 5;
  const Frame a0 = timing_frame(kWidth, kHeight, 0), b0 = timing_frame(kWidth, kHeight, 8);
  const size_t n = a0.pixel_count();
  std::vector<uint64_t> message(n + 2);
  std::vector<double> scan_ns, encode_ns, merge_ns, dense_ns;
  for (int run = 0; run <= kRuns; ++run) {
    Frame a = a0, b = b0;
    double t0 = thread_cpu_ms();
    const ActiveScan scan = scan_active_pixels(a);
    double t1 = thread_cpu_ms();
    const double scan_ms = t1 - t0;
    const ActiveScan scan_b = scan_active_pixels(b);
    const EmptyPixel empty = empty_pixel(std::max(scan.max_key, scan_b.max_key));
    ActiveFrame from{&a, empty, scan.rect}, into{&b, empty, scan_b.rect};
    RunLengthEncoder encoder(PixelRange{0, n});
    t0 = thread_cpu_ms();
    const size_t words = encoder.encode(from, message.data(), message.size());
    t1 = thread_cpu_ms();
    const double encode_ms = t1 - t0;
    RunLengthDecoder decoder(PixelRange{0, n});
    t0 = thread_cpu_ms();
    const Status decoded = decoder.decode(message.data(), words, into);
    t1 = thread_cpu_ms();
    const double merge_ms = t1 - t0;
    Frame c = b0;
    t0 = thread_cpu_ms();
    merge_pixels(a0.depth.data(), a0.rgba.data(), n, c.depth.data(), c.rgba.data());
    t1 = thread_cpu_ms();
    if (run == 0 || !decoded.ok() || scan.active == 0) continue;  // warm-up
    const double active = double(scan.active);
    scan_ns.push_back(scan_ms * 1e6 / double(n));
    encode_ns.push_back(encode_ms * 1e6 / active);
    merge_ns.push_back(merge_ms * 1e6 / active);
    dense_ns.push_back((t1 - t0) * 1e6 / double(n));
  }
  if (scan_ns.empty()) return;  // keeps the default figures
  model->scan_s = median(scan_ns) * 1e-9;
  model->encode_s = median(encode_ns) * 1e-9;
  model->merge_s = median(merge_ns) * 1e-9;
  model->dense_merge_s = median(dense_ns) * 1e-9;
}

}  // namespace

CompositeCostModel default_cost_model() {
  // tests/bench/composite.sh --calibrate on the 2-core development VM, Open MPI 4.1 over shared
  // memory, 2 ranks (tests/bench/composite/results/).
  CompositeCostModel m;
  m.latency_s = 2.0e-6;
  m.bytes_per_s = 4.0e9;
  // CPU figures measured by measure_cost_model there (lantern-bench-composite prints them).
  m.scan_s = 0.8e-9;
  m.encode_s = 3.0e-9;
  m.merge_s = 1.6e-9;
  m.dense_merge_s = 2.0e-9;
  m.measured = false;
  return m;
}

Status measure_cost_model(MPI_Comm comm, CompositeCostModel *model) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  *model = default_cost_model();
  double figures[6] = {model->latency_s, model->bytes_per_s, model->scan_s,
                       model->encode_s,  model->merge_s,     model->dense_merge_s};
  Status local;
  const int peer = ranks - 1;
  if (ranks >= 2 && (rank == 0 || rank == peer)) {
    constexpr size_t kLarge = size_t(1) << 20;
    std::vector<char> small(8, 0), large(kLarge, 0);
    double latency = 0.0, large_s = 0.0;
    local = ping_pong(comm, rank, peer, small, 2, 9, &latency);
    if (local.ok()) local = ping_pong(comm, rank, peer, large, 1, 5, &large_s);
    if (local.ok() && rank == 0) {
      figures[0] = latency;
      // The large message's time beyond one latency is its bytes at the bandwidth.
      figures[1] = double(kLarge) / std::max(large_s - latency, 1e-9);
      CompositeCostModel cpu = *model;
      measure_cpu_costs(&cpu);
      figures[2] = cpu.scan_s, figures[3] = cpu.encode_s;
      figures[4] = cpu.merge_s, figures[5] = cpu.dense_merge_s;
    }
  }
  // The other ranks wait asleep, so that where ranks share cores the pair and the timings get
  // them: the figures are the transport's and the pixel loops', not the time-sharing's (on a
  // machine with a core per rank this changes nothing).
  MPI_Request quiet;
  int rc = MPI_Ibarrier(comm, &quiet);
  const bool measuring = rank == 0 || rank == peer;
  for (int done = 0; rc == MPI_SUCCESS && !done;) {
    rc = MPI_Test(&quiet, &done, MPI_STATUS_IGNORE);
    if (!done && !measuring) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (rc == MPI_SUCCESS) rc = MPI_Bcast(figures, 6, MPI_DOUBLE, 0, comm);
  if (!local.ok()) return local;
  if (rc != MPI_SUCCESS) return mpi_error(rc, "broadcasting compositing's cost model");
  model->latency_s = figures[0];
  model->bytes_per_s = figures[1];
  model->scan_s = figures[2], model->encode_s = figures[3];
  model->merge_s = figures[4], model->dense_merge_s = figures[5];
  model->measured = ranks >= 2;
  return {};
}

long long cost_model_fingerprint(const CompositeCostModel &model,
                                 const std::optional<CompositingSchedule> &forced) {
  // FNV-1a over the figures' bits and the radices.
  uint64_t h = 1469598103934665603ull;
  const auto mix = [&h](uint64_t v) {
    for (int b = 0; b < 8; ++b) h = (h ^ ((v >> (8 * b)) & 0xff)) * 1099511628211ull;
  };
  uint64_t bits;
  std::memcpy(&bits, &model.latency_s, sizeof bits);
  mix(bits);
  for (const double v :
       {model.bytes_per_s, model.scan_s, model.encode_s, model.merge_s, model.dense_merge_s}) {
    std::memcpy(&bits, &v, sizeof bits);
    mix(bits);
  }
  if (forced) {
    mix(forced->tree ? 1 : 2);
    for (const int k : forced->radices) mix(uint64_t(k));
  }
  return static_cast<long long>(h);
}

CostEstimate estimate_active_pixels(const CompositingSchedule &schedule, size_t pixels,
                                    size_t active, bool to_root, const CompositeCostModel &model) {
  const double n = double(pixels), a = double(std::min(active, pixels));
  const double per_byte = 1.0 / model.bytes_per_s;
  const double one_way = std::max(model.encode_s, model.merge_s);  // per pixel of a stream
  const double both_ways = model.encode_s + model.merge_s;         // per pixel of an exchange
  const auto covered = [&](double images) { return n > 0 ? std::min(1.0, images * a / n) : 0.0; };
  CostEstimate e;
  e.seconds = model.scan_s * n;
  if (schedule.tree) {
    // Round j: the root takes a frame holding 2^j ranks' images.
    for (int64_t images = 1; images < int64_t(schedule.ranks); images *= 2) {
      const double moved = n * covered(double(images));
      e.seconds += model.latency_s + kBytesPerPixel * moved * per_byte + one_way * moved;
      e.bytes_sent = kBytesPerPixel * moved;  // the last sender's is the largest
    }
    e.messages_sent = 1;
    return e;
  }
  double images = 1.0;  // ranks' images merged into what a rank holds
  if (schedule.extras() > 0) {
    const double bytes = kBytesPerPixel * a;  // an extra rank's whole frame
    e.seconds += model.latency_s + bytes * per_byte + one_way * a;
    e.bytes_sent += bytes;
    e.messages_sent += 1;
    images = 2.0;
  }
  double region = n;
  for (const int k : schedule.radices) {
    const double moved = region * covered(images) * double(k - 1) / k;
    const double bytes = kBytesPerPixel * moved;
    e.seconds += double(k - 1) * model.latency_s + bytes * per_byte + both_ways * moved;
    e.bytes_sent += bytes;
    e.messages_sent += k - 1;
    region /= k;
    images *= k;
  }
  const double q = double(schedule.base());
  const double final_cover = covered(double(schedule.ranks));
  if (to_root) {
    // The root receives every other group's block; each of those sends one.
    // The senders encode their blocks side by side while the root merges all of them.
    const double moved = n * final_cover * (q - 1) / q;
    e.seconds += (q - 1) * model.latency_s + kBytesPerPixel * moved * per_byte +
                 std::max(model.encode_s * n * final_cover / q, model.merge_s * moved);
    e.bytes_sent += kBytesPerPixel * n * final_cover / q;
    e.messages_sent += 1;
  } else if (schedule.extras() > 0) {
    const double moved = n * final_cover / double(schedule.ranks);
    e.seconds += model.latency_s + kBytesPerPixel * moved * per_byte + one_way * moved;
    e.bytes_sent += kBytesPerPixel * moved;
    e.messages_sent += 1;
  }
  return e;
}

CostEstimate estimate_reduce64(int ranks, size_t pixels, const CompositeCostModel &model) {
  const double rounds = std::ceil(std::log2(double(std::max(ranks, 2))));
  const double bytes = kBytesPerPixel * double(pixels);
  CostEstimate e;
  e.seconds =
      rounds * (model.latency_s + bytes / model.bytes_per_s + model.dense_merge_s * double(pixels));
  e.bytes_sent = bytes;
  e.messages_sent = 1;
  return e;
}

CostEstimate estimate_dense_binary_swap(int ranks, size_t pixels, const CompositeCostModel &model) {
  const double n = double(pixels), per_byte = 1.0 / model.bytes_per_s;
  int q = 1;
  while (q * 2 <= ranks) q *= 2;
  CostEstimate e;
  if (q < ranks) {  // an extra rank's whole frame, merged by its base rank
    e.seconds += model.latency_s + kBytesPerPixel * n * per_byte + model.dense_merge_s * n;
    e.bytes_sent += kBytesPerPixel * n;
    e.messages_sent += 1;
  }
  double region = n;
  for (int bit = 1; bit < q; bit <<= 1) {
    region /= 2;
    const double moved = region;  // the half given away, and the partner's half taken
    e.seconds += model.latency_s + kBytesPerPixel * moved * per_byte + model.dense_merge_s * moved;
    e.bytes_sent += kBytesPerPixel * moved;
    e.messages_sent += 1;
  }
  // The root's gather: q - 1 blocks written into its frame by MPI.
  e.seconds += double(q - 1) * model.latency_s + kBytesPerPixel * n * double(q - 1) / q * per_byte;
  e.bytes_sent += kBytesPerPixel * n / q;
  e.messages_sent += 1;
  return e;
}

CompositingSchedule cheapest_schedule(int ranks, size_t pixels, size_t active, bool to_root,
                                      const CompositeCostModel &model, CostEstimate *estimate) {
  const std::vector<CompositingSchedule> candidates = candidate_schedules(ranks, to_root);
  size_t best = 0;
  CostEstimate best_estimate;
  for (size_t i = 0; i < candidates.size(); ++i) {
    const CostEstimate e = estimate_active_pixels(candidates[i], pixels, active, to_root, model);
    if (i == 0 || e.seconds < best_estimate.seconds) best = i, best_estimate = e;
  }
  if (estimate) *estimate = best_estimate;
  return candidates[best];
}

}  // namespace lantern
