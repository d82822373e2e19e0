#include "spatial_split.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/vec3.hpp>

#include "core/bricks/morton.h"

namespace lantern {
namespace {

// The curve is cut at 30-bit key prefixes (cells of 1/1024 of the frame's extent per axis), found
// in two rounds of counting: 2^18 coarse cells, then 2^12 fine cells inside the coarse cells that
// hold a cut.
constexpr int kCutBits = 30;
constexpr int kFineBits = 12;
constexpr int kCoarseBits = kCutBits - kFineBits;

// In a histogram (counts, summed over ranks), the first cell of each rank r >= 1 when cut where
// the running count reaches r/R of `total`: a cell goes to the rank whose share holds its middle.
// `before` is the count ahead of the histogram; returns per cut r the cell, or -1 when the cut
// is elsewhere.
void place_cuts(const std::vector<int64_t> &counts, int64_t before, int64_t total, int ranks,
                std::vector<int64_t> *cut_cell) {
  for (size_t k = 0; k < counts.size(); ++k) {
    const double middle = double(before) + 0.5 * double(counts[k]);
    const int owner = total > 0 ? std::min(ranks - 1, int(middle * ranks / double(total))) : 0;
    for (int r = 1; r <= owner; ++r)
      if ((*cut_cell)[size_t(r)] < 0) (*cut_cell)[size_t(r)] = int64_t(k);
    before += counts[k];
  }
}

// Sends this rank's values, grouped by destination (send_counts elements per rank, `width`
// values per particle), and returns what the other ranks sent, in rank order.
template <typename T>
std::vector<T> exchange(MPI_Comm comm, MPI_Datatype type, const std::vector<T> &values,
                        const std::vector<int64_t> &order, int width,
                        const std::vector<int> &send_counts, const std::vector<int> &recv_counts) {
  const int ranks = int(send_counts.size());
  std::vector<T> packed(order.size() * size_t(width));
  for (size_t k = 0; k < order.size(); ++k)
    for (int c = 0; c < width; ++c)
      packed[k * size_t(width) + size_t(c)] = values[size_t(order[k]) * size_t(width) + size_t(c)];
  const auto n = static_cast<size_t>(ranks);
  std::vector<int> sc(n), sd(n), rc(n), rd(n);
  int s = 0, r = 0;
  for (int k = 0; k < ranks; ++k) {
    sc[size_t(k)] = send_counts[size_t(k)] * width, sd[size_t(k)] = s, s += sc[size_t(k)];
    rc[size_t(k)] = recv_counts[size_t(k)] * width, rd[size_t(k)] = r, r += rc[size_t(k)];
  }
  std::vector<T> received(static_cast<size_t>(r));
  MPI_Alltoallv(packed.data(), sc.data(), sd.data(), type, received.data(), rc.data(), rd.data(),
                type, comm);
  return received;
}

}  // namespace

std::string split_spatially(MPI_Comm comm, ParticleFrame *frame, SplitStats *stats) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const int64_t n = frame->count();
  // The frame's bounds over every rank's finite positions.
  double bounds[6] = {INFINITY, INFINITY, INFINITY, INFINITY, INFINITY, INFINITY};  // lo, -hi
  std::vector<uint8_t> finite(static_cast<size_t>(n));
  for (int64_t i = 0; i < n; ++i) {
    const double *p = frame->position.data() + 3 * i;
    finite[size_t(i)] = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
    if (!finite[size_t(i)]) continue;
    for (int c = 0; c < 3; ++c)
      bounds[c] = std::min(bounds[c], p[c]), bounds[3 + c] = std::min(bounds[3 + c], -p[c]);
  }
  MPI_Allreduce(MPI_IN_PLACE, bounds, 6, MPI_DOUBLE, MPI_MIN, comm);
  int64_t total = 0;
  MPI_Allreduce(&n, &total, 1, MPI_INT64_T, MPI_SUM, comm);
  // Each finite particle's key prefix over those bounds, counted in coarse cells.
  const MortonQuantiser q = MortonQuantiser::for_bounds({bounds[0], bounds[1], bounds[2]},
                                                        {-bounds[3], -bounds[4], -bounds[5]});
  std::vector<uint32_t> key(static_cast<size_t>(n));
  std::vector<int64_t> coarse(size_t(1) << kCoarseBits, 0);
  for (int64_t i = 0; i < n; ++i) {
    if (!finite[size_t(i)]) continue;
    const double *p = frame->position.data() + 3 * i;
    key[size_t(i)] = uint32_t(q.key({p[0], p[1], p[2]}) >> (3 * kMortonBitsPerAxis - kCutBits));
    ++coarse[key[size_t(i)] >> kFineBits];
  }
  MPI_Allreduce(MPI_IN_PLACE, coarse.data(), int(coarse.size()), MPI_INT64_T, MPI_SUM, comm);
  int64_t on_curve = 0;
  for (const int64_t c : coarse) on_curve += c;
  // Round 1: the coarse cell of each cut. Round 2: the fine cell inside it, from the counts of the
  // coarse cells holding a cut (at most ranks - 1 of them).
  std::vector<int64_t> cut_coarse(size_t(ranks), -1);
  place_cuts(coarse, 0, on_curve, ranks, &cut_coarse);
  std::vector<int64_t> refined;  // the coarse cells holding a cut, ascending
  for (int r = 1; r < ranks; ++r)
    if (cut_coarse[size_t(r)] >= 0 && (refined.empty() || refined.back() != cut_coarse[size_t(r)]))
      refined.push_back(cut_coarse[size_t(r)]);
  const size_t fine_cells = size_t(1) << kFineBits;
  std::vector<int64_t> fine(refined.size() * fine_cells, 0);
  for (int64_t i = 0; i < n; ++i) {
    if (!finite[size_t(i)]) continue;
    const auto at =
        std::lower_bound(refined.begin(), refined.end(), int64_t(key[size_t(i)] >> kFineBits));
    if (at != refined.end() && *at == int64_t(key[size_t(i)] >> kFineBits))
      ++fine[size_t(at - refined.begin()) * fine_cells + (key[size_t(i)] & (fine_cells - 1))];
  }
  if (!fine.empty())
    MPI_Allreduce(MPI_IN_PLACE, fine.data(), int(fine.size()), MPI_INT64_T, MPI_SUM, comm);
  // Each rank r >= 1 starts at key prefix first_key[r]; ranks past the last particle start at
  // the end of the curve.
  std::vector<uint32_t> first_key(size_t(ranks), 0);
  for (int r = 1; r < ranks; ++r) first_key[size_t(r)] = ~0u;
  int64_t before = 0;
  size_t next = 0;
  for (size_t c = 0; c < coarse.size() && next < refined.size(); ++c) {
    if (int64_t(c) == refined[next]) {
      const std::vector<int64_t> cell(fine.begin() + long(next * fine_cells),
                                      fine.begin() + long((next + 1) * fine_cells));
      std::vector<int64_t> cut_fine(size_t(ranks), -1);
      place_cuts(cell, before, on_curve, ranks, &cut_fine);
      for (int r = 1; r < ranks; ++r)
        if (cut_coarse[size_t(r)] == int64_t(c) && cut_fine[size_t(r)] >= 0)
          first_key[size_t(r)] = uint32_t(c << kFineBits | size_t(cut_fine[size_t(r)]));
        else if (cut_coarse[size_t(r)] == int64_t(c))  // the whole cell went to earlier ranks
          first_key[size_t(r)] = uint32_t((c + 1) << kFineBits);
      ++next;
    }
    before += coarse[c];
  }
  for (int r = ranks - 1; r >= 1; --r)  // keep the starts ascending (empty ranks take the next)
    if (r + 1 < ranks)
      first_key[size_t(r)] = std::min(first_key[size_t(r)], first_key[size_t(r + 1)]);
  // Destinations; particles off the curve stay here. Grouped by destination, in row order.
  std::vector<int> send(size_t(ranks), 0), recv(size_t(ranks), 0);
  std::vector<int> dest(static_cast<size_t>(n));
  for (int64_t i = 0; i < n; ++i) {
    dest[size_t(i)] =
        finite[size_t(i)]
            ? int(std::upper_bound(first_key.begin() + 1, first_key.end(), key[size_t(i)]) -
                  first_key.begin()) -
                  1
            : rank;
    ++send[size_t(dest[size_t(i)])];
  }
  std::vector<int64_t> order(static_cast<size_t>(n));
  {
    std::vector<int64_t> at(size_t(ranks), 0);
    for (int k = 1; k < ranks; ++k) at[size_t(k)] = at[size_t(k - 1)] + send[size_t(k - 1)];
    for (int64_t i = 0; i < n; ++i) order[size_t(at[size_t(dest[size_t(i)])]++)] = i;
  }
  MPI_Alltoall(send.data(), 1, MPI_INT, recv.data(), 1, MPI_INT, comm);
  int64_t received = 0;
  for (const int c : recv) received += c;
  // MPI counts are ints: three coordinates per particle must fit, on every rank alike.
  constexpr int64_t kMost = std::numeric_limits<int>::max() / 3;
  int too_many = received > kMost || n > kMost;
  MPI_Allreduce(MPI_IN_PLACE, &too_many, 1, MPI_INT, MPI_MAX, comm);
  if (too_many)
    return "the spatial split would give a rank more than " + std::to_string(kMost) +
           " particles; use more ranks";
  // Each array the frame has, exchanged the same way. A rank that read no rows may lack an array
  // the others have: the ranks agree on which to exchange.
  int present[4] = {!frame->type.empty(), !frame->id.empty(), !frame->scalar.empty(),
                    !frame->radius.empty()};
  MPI_Allreduce(MPI_IN_PLACE, present, 4, MPI_INT, MPI_MAX, comm);
  frame->position = exchange(comm, MPI_DOUBLE, frame->position, order, 3, send, recv);
  if (present[0]) frame->type = exchange(comm, MPI_INT64_T, frame->type, order, 1, send, recv);
  if (present[1]) frame->id = exchange(comm, MPI_INT64_T, frame->id, order, 1, send, recv);
  if (present[2]) frame->scalar = exchange(comm, MPI_DOUBLE, frame->scalar, order, 1, send, recv);
  if (present[3]) frame->radius = exchange(comm, MPI_DOUBLE, frame->radius, order, 1, send, recv);
  // The ranks' counts: least, most and mean.
  int64_t spread[2] = {received, -received};
  MPI_Allreduce(MPI_IN_PLACE, spread, 2, MPI_INT64_T, MPI_MIN, comm);
  stats->least = spread[0];
  stats->most = -spread[1];
  stats->mean = double(total) / ranks;
  return {};
}

}  // namespace lantern
