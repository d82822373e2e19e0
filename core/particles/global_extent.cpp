#include "core/particles/global_extent.h"

#include <algorithm>
#include <cmath>

namespace lantern {
namespace {

// Everything that reduces by MIN, with maxima negated so one MPI_MIN handles both.
constexpr int kMinFields = 9;
void to_min_fields(const Extent &e, double out[kMinFields]) {
  for (int k = 0; k < 3; ++k) {
    out[k] = e.lo[k];
    out[3 + k] = -e.hi[k];
  }
  out[6] = -e.max_radius;
  out[7] = e.scalar_min;
  out[8] = -e.scalar_max;
}
void from_min_fields(const double in[kMinFields], Extent *e) {
  for (int k = 0; k < 3; ++k) {
    e->lo[k] = in[k];
    e->hi[k] = -in[3 + k];
  }
  e->max_radius = -in[6];
  e->scalar_min = in[7];
  e->scalar_max = -in[8];
}

}  // namespace

bool Extent::add_particle(double x, double y, double z, double radius) {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
    ++nonfinite_count;
    return false;
  }
  const double p[3] = {x, y, z};
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::min(lo[k], p[k]);
    hi[k] = std::max(hi[k], p[k]);
  }
  if (std::isfinite(radius)) max_radius = std::max(max_radius, radius);
  ++finite_count;
  return true;
}

void Extent::add_scalar(double value) {
  if (!std::isfinite(value)) return;
  scalar_min = std::min(scalar_min, value);
  scalar_max = std::max(scalar_max, value);
}

Extent merge_extents(const Extent &a, const Extent &b) {
  double fa[kMinFields], fb[kMinFields];
  to_min_fields(a, fa);
  to_min_fields(b, fb);
  for (int k = 0; k < kMinFields; ++k) fa[k] = std::min(fa[k], fb[k]);
  Extent out;
  from_min_fields(fa, &out);
  out.finite_count = a.finite_count + b.finite_count;
  out.nonfinite_count = a.nonfinite_count + b.nonfinite_count;
  return out;
}

Extent reduce_extent(MPI_Comm comm, const Extent &local) {
  double mins[kMinFields];
  to_min_fields(local, mins);
  MPI_Allreduce(MPI_IN_PLACE, mins, kMinFields, MPI_DOUBLE, MPI_MIN, comm);
  int64_t counts[2] = {local.finite_count, local.nonfinite_count};
  MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_INT64_T, MPI_SUM, comm);
  Extent global;
  from_min_fields(mins, &global);
  global.finite_count = counts[0];
  global.nonfinite_count = counts[1];
  return global;
}

}  // namespace lantern
