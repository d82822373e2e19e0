#include "core/render/object_occlusion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <glm/geometric.hpp>

namespace lantern {

namespace {

// The cell grid over the global bounds.
struct Grid {
  glm::dvec3 lo{0.0};
  double cell = 1.0;
  std::array<int, 3> n{1, 1, 1};

  Grid(const Extent &global, double wanted_cell) {
    double longest = 0.0;
    for (int a = 0; a < 3; ++a) longest = std::max(longest, global.hi[a] - global.lo[a]);
    cell = std::max(wanted_cell, longest / kMaxOcclusionCells);
    if (!(cell > 0.0)) cell = 1.0;
    for (int a = 0; a < 3; ++a) {
      lo[a] = global.lo[a];
      n[a] = std::clamp(int(std::floor((global.hi[a] - global.lo[a]) / cell)) + 1, 1,
                        kMaxOcclusionCells);
    }
  }
  size_t size() const { return size_t(n[0]) * size_t(n[1]) * size_t(n[2]); }
  std::array<int, 3> cell_of(const glm::dvec3 &p) const {
    std::array<int, 3> c;
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(int(std::floor((p[a] - lo[a]) / cell)), 0, n[a] - 1);
    return c;
  }
  size_t index(int x, int y, int z) const {
    return (size_t(z) * size_t(n[1]) + size_t(y)) * size_t(n[0]) + size_t(x);
  }
};

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

// The sums of the 3 x 3 x 3 counts around every cell (cells outside the grid count as empty),
// as three separable passes.
std::vector<double> neighbourhood_sums(const Grid &g, const std::vector<int64_t> &counts) {
  std::vector<double> a(counts.begin(), counts.end()), b(a.size());
  for (int axis = 0; axis < 3; ++axis) {
    const size_t step = axis == 0 ? 1 : axis == 1 ? size_t(g.n[0]) : size_t(g.n[0]) * g.n[1];
    for (int z = 0; z < g.n[2]; ++z)
      for (int y = 0; y < g.n[1]; ++y)
        for (int x = 0; x < g.n[0]; ++x) {
          const int at = axis == 0 ? x : axis == 1 ? y : z;
          const size_t i = g.index(x, y, z);
          double sum = a[i];
          if (at > 0) sum += a[i - step];
          if (at + 1 < g.n[axis]) sum += a[i + step];
          b[i] = sum;
        }
    a.swap(b);
  }
  return a;
}

// The neighbourhood sum at x, trilinear between cell centres (clamped at the grid's faces), so
// the factor varies smoothly from particle to particle.
double sum_at(const Grid &g, const std::vector<double> &sums, const glm::dvec3 &x) {
  int i0[3];
  double t[3];
  for (int a = 0; a < 3; ++a) {
    const double u = std::clamp((x[a] - g.lo[a]) / g.cell - 0.5, 0.0, double(g.n[a] - 1));
    i0[a] = std::min(int(u), std::max(g.n[a] - 2, 0));
    t[a] = g.n[a] > 1 ? u - i0[a] : 0.0;
  }
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    double w = 1.0;
    int c[3];
    for (int a = 0; a < 3; ++a) {
      const int up = (corner >> a) & 1;
      c[a] = std::min(i0[a] + up, g.n[a] - 1);
      w *= up ? t[a] : 1.0 - t[a];
    }
    if (w > 0.0) value += w * sums[g.index(c[0], c[1], c[2])];
  }
  return value;
}

}  // namespace

Status object_occlusion(MPI_Comm comm, const ParticleArrays &particles, const Extent &global,
                        const std::vector<CutPlane> &cuts, double cell, double strength,
                        std::vector<float> *factor) {
  factor->assign(size_t(particles.count()), 1.0f);
  if (global.empty()) return {};  // the same on every rank: no reduction to skip
  const Grid g(global, cell);
  std::vector<int64_t> local(g.size(), 0), counts(g.size(), 0);
  glm::dvec3 x;
  for (int64_t i = 0; i < particles.count(); ++i)
    if (drawn(particles, cuts, i, &x)) {
      const std::array<int, 3> c = g.cell_of(x);
      ++local[g.index(c[0], c[1], c[2])];
    }
  // One reduction of integers: exact, so every split gives the same volume.
  if (MPI_Allreduce(local.data(), counts.data(), int(g.size()), MPI_INT64_T, MPI_SUM, comm) !=
      MPI_SUCCESS)
    return {StatusCode::kMpi, "ambient_occlusion (object): MPI_Allreduce of the density failed"};
  const int64_t fullest = std::max<int64_t>(1, *std::max_element(counts.begin(), counts.end()));
  const std::vector<double> sums = neighbourhood_sums(g, counts);
  for (int64_t i = 0; i < particles.count(); ++i) {
    if (!drawn(particles, cuts, i, &x)) continue;
    const double occupancy = sum_at(g, sums, x) / (27.0 * double(fullest));
    (*factor)[size_t(i)] = float(1.0 - strength * std::clamp(2.0 * occupancy - 1.0, 0.0, 1.0));
  }
  return {};
}

}  // namespace lantern
