// What every rank must agree on before a collective compositing step, settled in one
// MPI_Allreduce(MPI_MIN) of long longs: values that must be equal everywhere (each sent as x and
// ~x, so that min and max come back together: max(x) = ~min(~x), for every bit pattern), maxima
// over the ranks (sent as ~x), minima (sent as x) and flags that must hold everywhere (min).
//
// Usage: add every field in the same order on every rank, reduce() once, then read them back by
// the index add returned. Collective in reduce() only.
#pragma once

#include <mpi.h>

#include <cstddef>
#include <vector>

#include "core/common/status.h"

namespace lantern {

class RankAgreement {
 public:
  size_t equal(long long value);    // agreed(i): the same on every rank
  size_t maximum(long long value);  // max(i): the largest over the ranks
  size_t minimum(long long value);  // min(i): the smallest over the ranks
  size_t all(bool value);           // holds(i): true on every rank

  // One MPI_Allreduce over comm. OK or kMpi.
  Status reduce(MPI_Comm comm);

  bool agreed(size_t i) const { return values_[i] == ~values_[i + 1]; }
  long long max(size_t i) const { return ~values_[i]; }
  long long min(size_t i) const { return values_[i]; }
  bool holds(size_t i) const { return values_[i] != 0; }

 private:
  std::vector<long long> values_;
};

}  // namespace lantern
