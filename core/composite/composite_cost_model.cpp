#include "core/composite/composite_cost_model.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/composite/composite_methods.h"

namespace lantern {
namespace {

constexpr double kBytesPerPixel = 8.0;  // a packed key: depth bits and RGBA8
constexpr int kPingTag = 0x4c60;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Half the median round trip of `bytes`-byte messages between rank 0 and `peer` (on rank 0; the
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
  *seconds = median(trips) / 2;
  return {};
}

}  // namespace

CompositeCostModel default_cost_model() {
  // tests/bench/composite.sh --calibrate on the 2-core development VM, Open MPI 4.1 over shared
  // memory, 2 ranks (tests/bench/composite/results/).
  CompositeCostModel m;
  m.latency_s = 2.0e-6;
  m.bytes_per_s = 4.0e9;
  m.measured = false;
  return m;
}

Status measure_cost_model(MPI_Comm comm, CompositeCostModel *model) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  *model = default_cost_model();
  double figures[2] = {model->latency_s, model->bytes_per_s};
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
    }
  }
  const int rc = MPI_Bcast(figures, 2, MPI_DOUBLE, 0, comm);
  if (!local.ok()) return local;
  if (rc != MPI_SUCCESS) return mpi_error(rc, "broadcasting compositing's cost model");
  model->latency_s = figures[0];
  model->bytes_per_s = figures[1];
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
  std::memcpy(&bits, &model.bytes_per_s, sizeof bits);
  mix(bits);
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
  const auto covered = [&](double images) { return n > 0 ? std::min(1.0, images * a / n) : 0.0; };
  CostEstimate e;
  if (schedule.tree) {
    // Round j: the root takes a frame holding 2^j ranks' images.
    for (double images = 1; images < double(schedule.ranks); images *= 2) {
      const double bytes = kBytesPerPixel * n * covered(images);
      e.seconds += model.latency_s + bytes * per_byte;
      e.bytes_sent = bytes;  // the last sender's is the largest
    }
    e.messages_sent = 1;
    return e;
  }
  double images = 1.0;  // ranks' images merged into what a rank holds
  if (schedule.extras() > 0) {
    const double bytes = kBytesPerPixel * a;  // an extra rank's whole frame
    e.seconds += model.latency_s + bytes * per_byte;
    e.bytes_sent += bytes;
    e.messages_sent += 1;
    images = 2.0;
  }
  double region = n;
  for (const int k : schedule.radices) {
    const double bytes = kBytesPerPixel * region * covered(images) * double(k - 1) / k;
    e.seconds += double(k - 1) * model.latency_s + bytes * per_byte;
    e.bytes_sent += bytes;
    e.messages_sent += k - 1;
    region /= k;
    images *= k;
  }
  const double q = double(schedule.base());
  const double final_cover = covered(double(schedule.ranks));
  if (to_root) {
    // The root receives every other group's block; each of those sends one.
    const double bytes = kBytesPerPixel * n * final_cover * (q - 1) / q;
    e.seconds += (q - 1) * model.latency_s + bytes * per_byte;
    e.bytes_sent += kBytesPerPixel * n * final_cover / q;
    e.messages_sent += 1;
  } else if (schedule.extras() > 0) {
    const double bytes = kBytesPerPixel * n * final_cover / double(schedule.ranks);
    e.seconds += model.latency_s + bytes * per_byte;
    e.bytes_sent += bytes;
    e.messages_sent += 1;
  }
  return e;
}

CostEstimate estimate_reduce64(int ranks, size_t pixels, const CompositeCostModel &model) {
  const double rounds = std::ceil(std::log2(double(std::max(ranks, 2))));
  const double bytes = kBytesPerPixel * double(pixels);
  CostEstimate e;
  e.seconds = rounds * (model.latency_s + bytes / model.bytes_per_s);
  e.bytes_sent = bytes;
  e.messages_sent = 1;
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
