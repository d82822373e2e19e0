#include "core/pipeline/rank_spread.h"

#include <algorithm>

namespace lantern {
namespace {

// One value's partial reduction: least, greatest, rank of the greatest, sum.
struct Partial {
  double min, max, max_rank, sum;
};

// MPI_User_function: combines `in` into `inout`. Commutative: on equal maxima the lower rank
// wins whatever the order the implementation combines in.
void combine(void *in, void *inout, int *len, MPI_Datatype *) {
  const auto *a = static_cast<const Partial *>(in);
  auto *b = static_cast<Partial *>(inout);
  for (int i = 0; i < *len; ++i) {
    if (a[i].max > b[i].max || (a[i].max == b[i].max && a[i].max_rank < b[i].max_rank))
      b[i].max = a[i].max, b[i].max_rank = a[i].max_rank;
    b[i].min = std::min(a[i].min, b[i].min);
    b[i].sum += a[i].sum;
  }
}

}  // namespace

nlohmann::json RankSpread::to_json() const {
  return {{"min", min},
          {"max", max},
          {"mean", mean},
          {"imbalance", imbalance()},
          {"max_rank", max_rank}};
}

nlohmann::json PerRankStats::to_json() const {
  return {{"drawn", drawn.to_json()},
          {"culled", culled.to_json()},
          {"ms", ms.to_json()},
          {"particles", particles.to_json()}};
}

std::vector<RankSpread> reduce_rank_spreads(MPI_Comm comm, int root,
                                            const std::vector<double> &local) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const size_t n = local.size();
  std::vector<Partial> mine(n), all(n);
  for (size_t i = 0; i < n; ++i) mine[i] = {local[i], local[i], double(rank), local[i]};
  // Created per call: a few microseconds, and nothing global to free at MPI_Finalize.
  MPI_Datatype type;
  MPI_Type_contiguous(4, MPI_DOUBLE, &type);
  MPI_Type_commit(&type);
  MPI_Op op;
  MPI_Op_create(&combine, 1, &op);
  MPI_Reduce(mine.data(), all.data(), int(n), type, op, root, comm);
  MPI_Op_free(&op);
  MPI_Type_free(&type);
  std::vector<RankSpread> out(n);
  if (rank != root) return out;
  for (size_t i = 0; i < n; ++i)
    out[i] = {all[i].min, all[i].max, all[i].sum / size, int(all[i].max_rank)};
  return out;
}

PerRankStats reduce_per_rank_stats(MPI_Comm comm, int root, double drawn, double culled, double ms,
                                   double particles) {
  const std::vector<RankSpread> spread =
      reduce_rank_spreads(comm, root, {drawn, culled, ms, particles});
  return {spread[0], spread[1], spread[2], spread[3]};
}

}  // namespace lantern
