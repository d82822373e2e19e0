#include "core/composite/row_bands.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <string>
#include <vector>

#include "core/common/collective_status.h"
#include "core/composite/composite_methods.h"

namespace lantern {
namespace {

// The rows rank k holds with its halo, clamped to the image.
RowBand with_halo(const RowBand &owned, int height, int halo) {
  if (owned.rows() == 0) return owned;
  return {std::max(0, owned.y0 - halo), std::min(height, owned.y1 + halo)};
}

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

}  // namespace

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

}  // namespace lantern
