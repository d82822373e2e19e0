#include "core/render/object_occlusion.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/geometric.hpp>

namespace lantern {

namespace {

bool drawn(const ParticleArrays &p, const std::vector<CutPlane> &cuts, int64_t i,
           glm::dvec3 *position) {
  if (!p.kept(i)) return false;
  const glm::dvec3 x = p.position(i);
  if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z)) return false;
  for (const CutPlane &c : cuts)
    if (c.enabled && glm::dot(glm::dvec3(c.normal[0], c.normal[1], c.normal[2]), x) > c.offset)
      return false;
  *position = x;
  return true;
}

}  // namespace

void OcclusionVolume::set_grid(const Extent &global, double cell) {
  double longest = 0.0;
  for (int a = 0; a < 3; ++a) longest = std::max(longest, global.hi[a] - global.lo[a]);
  cell_ = std::max(cell, longest / kMaxOcclusionCells);
  if (!(cell_ > 0.0)) cell_ = 1.0;
  for (int a = 0; a < 3; ++a) {
    lo_[a] = global.lo[a];
    n_[a] = std::clamp(int(std::floor((global.hi[a] - global.lo[a]) / cell_)) + 1, 1,
                       kMaxOcclusionCells);
  }
}

// The sums of the 3 x 3 x 3 counts around every cell (cells outside the grid count as empty),
// as three separable passes, in double (exact for these integer counts).
void OcclusionVolume::sum_neighbourhoods(const std::vector<int32_t> &counts) {
  std::vector<double> a(counts.begin(), counts.end()), b(a.size());
  for (int axis = 0; axis < 3; ++axis) {
    const size_t step = axis == 0 ? 1 : axis == 1 ? size_t(n_[0]) : size_t(n_[0]) * n_[1];
    for (int z = 0; z < n_[2]; ++z)
      for (int y = 0; y < n_[1]; ++y)
        for (int x = 0; x < n_[0]; ++x) {
          const int at = axis == 0 ? x : axis == 1 ? y : z;
          const size_t i = index(x, y, z);
          double sum = a[i];
          if (at > 0) sum += a[i - step];
          if (at + 1 < n_[axis]) sum += a[i + step];
          b[i] = sum;
        }
    a.swap(b);
  }
  sums_.assign(a.begin(), a.end());
}

Status OcclusionVolume::build(MPI_Comm comm, const ParticleArrays &particles, const Extent &global,
                              const std::vector<CutPlane> &cuts, double cell, double strength) {
  strength_ = strength;
  sums_.clear();
  if (global.empty()) return {};  // the same on every rank: no reduction to skip
  set_grid(global, cell);
  const size_t cells = size_t(n_[0]) * size_t(n_[1]) * size_t(n_[2]);
  std::vector<int32_t> local(cells, 0), counts(cells, 0);
  glm::dvec3 x;
  for (int64_t i = 0; i < particles.count(); ++i)
    if (drawn(particles, cuts, i, &x)) {
      int c[3];
      for (int a = 0; a < 3; ++a)
        c[a] = std::clamp(int(std::floor((x[a] - lo_[a]) / cell_)), 0, n_[a] - 1);
      // Saturating: a cell holding over 2^31 / ranks particles is full either way.
      int32_t &k = local[index(c[0], c[1], c[2])];
      if (k < INT32_MAX / 4096) ++k;
    }
  // One reduction of integers: exact, so every split gives the same volume.
  if (MPI_Allreduce(local.data(), counts.data(), int(cells), MPI_INT32_T, MPI_SUM, comm) !=
      MPI_SUCCESS)
    return {StatusCode::kMpi, "ambient_occlusion (object): MPI_Allreduce of the density failed"};
  full_ = 27.0 * std::max<int32_t>(1, *std::max_element(counts.begin(), counts.end()));
  sum_neighbourhoods(counts);
  return {};
}

float OcclusionVolume::factor(const glm::dvec3 &x) const {
  if (sums_.empty()) return 1.0f;
  // Trilinear between cell centres, clamped at the grid's faces.
  int i0[3];
  double t[3];
  for (int a = 0; a < 3; ++a) {
    const double u = std::clamp((x[a] - lo_[a]) / cell_ - 0.5, 0.0, double(n_[a] - 1));
    i0[a] = std::min(int(u), std::max(n_[a] - 2, 0));
    t[a] = n_[a] > 1 ? u - i0[a] : 0.0;
  }
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    double w = 1.0;
    int c[3];
    for (int a = 0; a < 3; ++a) {
      const int up = (corner >> a) & 1;
      c[a] = std::min(i0[a] + up, n_[a] - 1);
      w *= up ? t[a] : 1.0 - t[a];
    }
    if (w > 0.0) value += w * sums_[index(c[0], c[1], c[2])];
  }
  const double occupancy = value / full_;
  return float(1.0 - strength_ * std::clamp(2.0 * occupancy - 1.0, 0.0, 1.0));
}

}  // namespace lantern
