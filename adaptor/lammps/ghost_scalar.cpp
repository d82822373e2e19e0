#include "ghost_scalar.h"

#include <cstdint>
#include <cstring>

#include "lammps_internals.h"

namespace lantern_lammps {

void GhostScalar::extend(void *handle, const lantern_array owned, lantern_array *out) {
  auto *lmp = static_cast<LAMMPS_NS::LAMMPS *>(handle);
  const int nlocal = lmp->atom->nlocal, nghost = lmp->atom->nghost;
  std::vector<double> &values = values_[next_];
  values.resize(size_t(nlocal) + size_t(nghost));
  const int64_t stride = owned.stride_bytes != 0 ? owned.stride_bytes : int64_t(sizeof(double));
  const auto *bytes = static_cast<const unsigned char *>(owned.data);
  for (int i = 0; i < nlocal; ++i)  // memcpy: the stride need not keep doubles aligned
    std::memcpy(&values[size_t(i)], bytes + int64_t(i) * stride, sizeof(double));
  rows_.resize(values.size());
  for (size_t i = 0; i < values.size(); ++i) rows_[i] = &values[i];
  // Every rank takes part, atoms or not: a ghost can reach its rank through another's ghosts.
  lmp->comm->forward_comm_array(1, rows_.data());
  *out = nlocal > 0 ? lantern_array{values.data(), LANTERN_FLOAT64, 0} : lantern_array{};
  next_ = 1 - next_;
}

}  // namespace lantern_lammps
