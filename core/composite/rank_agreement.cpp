#include "core/composite/rank_agreement.h"

#include "core/composite/composite_methods.h"

namespace lantern {

size_t RankAgreement::equal(long long value) {
  values_.push_back(value);
  values_.push_back(~value);
  return values_.size() - 2;
}

size_t RankAgreement::maximum(long long value) {
  values_.push_back(~value);
  return values_.size() - 1;
}

size_t RankAgreement::minimum(long long value) {
  values_.push_back(value);
  return values_.size() - 1;
}

size_t RankAgreement::all(bool value) {
  values_.push_back(value ? 1 : 0);
  return values_.size() - 1;
}

Status RankAgreement::reduce(MPI_Comm comm) {
  const int rc = MPI_Allreduce(MPI_IN_PLACE, values_.data(), int(values_.size()), MPI_LONG_LONG,
                               MPI_MIN, comm);
  return mpi_error(rc, "compositing: agreeing on the frame");
}

}  // namespace lantern
