#include "core/composite/row_bands.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/common/collective_status.h"
#include "core/composite/composite_methods.h"

namespace lantern {
namespace {

// Pixel counts and offsets of every rank's rows, for the v-collectives; false if one does not
// fit an int.
bool counts_of(const std::vector<RowBand> &rows, int width, std::vector<int> *counts,
               std::vector<int> *offsets) {
  counts->resize(rows.size());
  offsets->resize(rows.size());
  for (size_t k = 0; k < rows.size(); ++k) {
    const int64_t count = int64_t(rows[k].rows()) * width;
    const int64_t offset = int64_t(rows[k].y0) * width;
    if (count > INT_MAX || offset > INT_MAX) return false;
    (*counts)[k] = int(count);
    (*offsets)[k] = int(offset);
  }
  return true;
}

// Tags of the halo rows' messages (other tags on a communicator Lantern uses: 0x4c50-0x4c60).
constexpr int kHaloColorTag = 0x4c48;
constexpr int kHaloDepthTag = kHaloColorTag + 1;

}  // namespace

RowBand with_halo(const RowBand &owned, int height, int halo) {
  if (owned.rows() == 0) return owned;
  return {std::max(0, owned.y0 - halo), std::min(height, owned.y1 + halo)};
}

RowBand row_band(int height, int ranks, int rank, int multiple) {
  const int64_t units = height / std::max(multiple, 1);  // blocks of `multiple` rows
  const int64_t base = units / ranks, extra = units % ranks;
  // The first `extra` ranks own one block more.
  const int64_t first = rank * base + std::min<int64_t>(rank, extra);
  const int64_t count = base + (rank < extra ? 1 : 0);
  return {int(first * multiple), int((first + count) * multiple)};
}

Status scatter_row_bands(MPI_Comm comm, int root, const Frame &full, int width, int height,
                         int multiple, int halo, BandFrame *band) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  std::vector<RowBand> held(static_cast<size_t>(ranks));
  for (int k = 0; k < ranks; ++k)
    held[size_t(k)] = with_halo(row_band(height, ranks, k, multiple), height, halo);
  std::vector<int> counts, offsets;
  Status fits;
  if (!counts_of(held, width, &counts, &offsets))
    fits = {StatusCode::kMpi, "row bands of a " + std::to_string(width) + " x " +
                                  std::to_string(height) + " image exceed INT_MAX pixels"};
  if (rank == root && fits.ok() && (full.width != width || full.height != height))
    fits = {StatusCode::kMpi, "scatter_row_bands: the root's frame is " +
                                  std::to_string(full.width) + " x " + std::to_string(full.height) +
                                  ", expected " + std::to_string(width) + " x " +
                                  std::to_string(height)};
  if (Status s = agree_on_status(comm, fits); !s.ok()) return s;

  const RowBand mine = held[size_t(rank)];
  band->owned = row_band(height, ranks, rank, multiple);
  band->first = mine.y0;
  band->frame.width = width;
  band->frame.height = mine.rows();
  band->frame.rgba.resize(size_t(mine.rows()) * size_t(width) * 4);
  band->frame.depth.resize(size_t(mine.rows()) * size_t(width));
  // Colour moves as one 32-bit word per pixel, depth as one float: two calls of pixel counts.
  const void *rgba = rank == root ? full.rgba.data() : nullptr;
  const void *depth = rank == root ? full.depth.data() : nullptr;
  int rc = MPI_Scatterv(rgba, counts.data(), offsets.data(), MPI_UINT32_T, band->frame.rgba.data(),
                        counts[size_t(rank)], MPI_UINT32_T, root, comm);
  if (rc == MPI_SUCCESS)
    rc = MPI_Scatterv(depth, counts.data(), offsets.data(), MPI_FLOAT, band->frame.depth.data(),
                      counts[size_t(rank)], MPI_FLOAT, root, comm);
  return agree_on_status(comm, mpi_error(rc, "MPI_Scatterv"));
}

Status gather_row_bands(MPI_Comm comm, int root, const BandFrame &band, int width, int height,
                        Frame *full) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  std::vector<RowBand> owned(static_cast<size_t>(ranks));
  for (int k = 0; k < ranks; ++k) owned[size_t(k)] = row_band(height, ranks, k, 1);
  std::vector<int> counts, offsets;
  Status fits;
  if (!counts_of(owned, width, &counts, &offsets))
    fits = {StatusCode::kMpi, "row bands of a " + std::to_string(width) + " x " +
                                  std::to_string(height) + " image exceed INT_MAX pixels"};
  const RowBand mine = owned[size_t(rank)];
  if (fits.ok() && (band.frame.width != width || band.first > mine.y0 ||
                    band.first + band.frame.height < mine.y1))
    fits = {StatusCode::kMpi, "gather_row_bands: rank " + std::to_string(rank) +
                                  "'s band does not hold its rows " + std::to_string(mine.y0) +
                                  ".." + std::to_string(mine.y1)};
  if (Status s = agree_on_status(comm, fits); !s.ok()) return s;

  if (rank == root) {
    full->width = width;
    full->height = height;
    full->rgba.resize(size_t(width) * size_t(height) * 4);
    full->depth.resize(size_t(width) * size_t(height));
  }
  const size_t skip = size_t(mine.y0 - band.first) * size_t(width);  // halo rows above
  uint8_t *rgba_out = rank == root ? full->rgba.data() : nullptr;
  float *depth_out = rank == root ? full->depth.data() : nullptr;
  int rc = MPI_Gatherv(band.frame.rgba.data() + 4 * skip, counts[size_t(rank)], MPI_UINT32_T,
                       rgba_out, counts.data(), offsets.data(), MPI_UINT32_T, root, comm);
  if (rc == MPI_SUCCESS)
    rc = MPI_Gatherv(band.frame.depth.data() + skip, counts[size_t(rank)], MPI_FLOAT, depth_out,
                     counts.data(), offsets.data(), MPI_FLOAT, root, comm);
  return agree_on_status(comm, mpi_error(rc, "MPI_Gatherv"));
}

Status exchange_halo_rows(MPI_Comm comm, int width, int height, int halo, BandFrame *band,
                          int multiple) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const RowBand owned = row_band(height, ranks, rank, multiple);
  const RowBand want = with_halo(owned, height, halo);
  const bool exact = band->first == owned.y0 && band->frame.height == owned.rows();
  const bool widened = band->first == want.y0 && band->frame.height == want.rows();
  const bool whole = band->first == 0 && band->frame.height == height;
  Status fits;
  if (band->frame.width != width || !(exact || widened || whole))
    fits = {StatusCode::kMpi, "exchange_halo_rows: rank " + std::to_string(rank) +
                                  "'s band is not exactly its rows " + std::to_string(owned.y0) +
                                  ".." + std::to_string(owned.y1) +
                                  " (nor them with their halo, nor the whole image)"};
  if (fits.ok() && int64_t(want.rows()) * width > INT_MAX)
    fits = {StatusCode::kMpi, "exchange_halo_rows: a band exceeds INT_MAX pixels"};
  if (Status s = agree_on_status(comm, fits); !s.ok()) return s;
  band->owned = owned;
  band->held = want;
  // No halo, or one rank: nothing to move (then the band is its rows, exactly). Decided alike
  // on every rank, which all pass the same `halo`: a rank whose own band needs nothing may still
  // have rows to send.
  if (halo <= 0 || ranks == 1) return {};

  // My own rows to their place among the halo rows, in the band's own buffers.
  Frame &f = band->frame;
  if (exact && !widened && !whole) {
    const size_t at = size_t(owned.y0 - want.y0) * size_t(width);
    const size_t mine = size_t(owned.rows()) * size_t(width);
    const size_t pixels = size_t(want.rows()) * size_t(width);
    f.rgba.resize(4 * pixels);
    f.depth.resize(pixels);
    std::copy_backward(f.rgba.begin(), f.rgba.begin() + ptrdiff_t(4 * mine),
                       f.rgba.begin() + ptrdiff_t(4 * (at + mine)));
    std::copy_backward(f.depth.begin(), f.depth.begin() + ptrdiff_t(mine),
                       f.depth.begin() + ptrdiff_t(at + mine));
    f.height = want.rows();
    band->first = want.y0;
  }
  // To rank k the rows of mine inside k's halo, from rank k the rows of k's inside mine: the
  // received rows are disjoint from the sent ones, so both use the band's buffers.
  const auto overlap = [](RowBand a, RowBand b) {
    const int y0 = std::max(a.y0, b.y0), y1 = std::min(a.y1, b.y1);
    return y1 > y0 ? RowBand{y0, y1} : RowBand{0, 0};
  };
  std::vector<MPI_Request> requests;
  int rc = MPI_SUCCESS;
  const auto post = [&](bool receive, RowBand rows, int k) {
    if (rows.rows() == 0 || rc != MPI_SUCCESS) return;
    const size_t at = size_t(rows.y0 - band->first) * size_t(width);
    const int count = rows.rows() * width;  // <= want.rows() * width <= INT_MAX
    uint8_t *rgba = f.rgba.data() + 4 * at;
    float *depth = f.depth.data() + at;
    for (int part = 0; part < 2 && rc == MPI_SUCCESS; ++part) {
      void *data = part == 0 ? static_cast<void *>(rgba) : static_cast<void *>(depth);
      const MPI_Datatype type = part == 0 ? MPI_UINT32_T : MPI_FLOAT;
      const int tag = part == 0 ? kHaloColorTag : kHaloDepthTag;
      requests.emplace_back();
      rc = receive ? MPI_Irecv(data, count, type, k, tag, comm, &requests.back())
                   : MPI_Isend(data, count, type, k, tag, comm, &requests.back());
      if (rc != MPI_SUCCESS) requests.pop_back();
    }
  };
  for (int k = 0; k < ranks; ++k) {
    if (k == rank) continue;
    const RowBand theirs = row_band(height, ranks, k, multiple);
    post(true, overlap(theirs, want), k);
    post(false, overlap(owned, with_halo(theirs, height, halo)), k);
  }
  const int waited = MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  if (rc == MPI_SUCCESS) rc = waited;
  return agree_on_status(comm, mpi_error(rc, "exchanging the halo rows"));
}

}  // namespace lantern
