#include "core/composite/density_sum.h"

#include <algorithm>
#include <string>

namespace lantern {

Status sum_density_to_root(MPI_Comm comm, int root, DensityImage *image) {
  constexpr size_t kChunk = size_t(1) << 26;
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const size_t n = image->sum.size();
  for (size_t at = 0; at < n; at += kChunk) {
    const int count = int(std::min(kChunk, n - at));
    int64_t *data = image->sum.data() + at;
    const int rc = rank == root
                       ? MPI_Reduce(MPI_IN_PLACE, data, count, MPI_INT64_T, MPI_SUM, root, comm)
                       : MPI_Reduce(data, nullptr, count, MPI_INT64_T, MPI_SUM, root, comm);
    if (rc != MPI_SUCCESS)
      return {StatusCode::kMpi,
              "summing density images: MPI_Reduce failed (" + std::to_string(rc) + ")"};
  }
  return {};
}

}  // namespace lantern
