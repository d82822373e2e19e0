#include "core/culling/cull_stats.h"

namespace lantern {

ProbabilisticStats reduce_probabilistic_stats(MPI_Comm comm, const ProbabilisticStats &local) {
  int64_t most[2] = {local.iterations, local.samples};
  int64_t sum[5] = {local.meshlets[0], local.meshlets[1], local.meshlets[2], local.meshlets[3],
                    local.particles_culled};
  MPI_Allreduce(MPI_IN_PLACE, most, 2, MPI_INT64_T, MPI_MAX, comm);
  MPI_Allreduce(MPI_IN_PLACE, sum, 5, MPI_INT64_T, MPI_SUM, comm);
  ProbabilisticStats all;
  all.iterations = most[0], all.samples = most[1];
  for (int k = 0; k < 4; ++k) all.meshlets[k] = sum[k];
  all.particles_culled = sum[4];
  return all;
}

}  // namespace lantern
