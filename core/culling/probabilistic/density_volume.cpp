#include "core/culling/probabilistic/density_volume.h"

#include <algorithm>
#include <cmath>

#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

namespace lantern {
namespace {

// Steps of the ray march per depth bin: enough for bins thinner than a voxel to see each voxel.
constexpr int kStepsPerBin = 4;

}  // namespace

void DensityVolume::reset(const glm::dvec3 &lo, const glm::dvec3 &hi, int64_t particles) {
  const glm::dvec3 ext = glm::max(hi - lo, glm::dvec3(1e-9));
  const double voxels = std::clamp(double(particles) / 8.0, 1.0, 64.0 * 64.0 * 64.0);
  cell_ = std::cbrt(ext.x * ext.y * ext.z / voxels);
  // Clamped before the conversion to int: a line of particles (two sides floored to 1e-9) puts
  // the first ratio far beyond int's range.
  const auto count = [this, &ext](int a) {
    return int(std::clamp(std::ceil(ext[a] / cell_), 1.0, 256.0));
  };
  for (int a = 0; a < 3; ++a) {
    n_[a] = count(a);
    cell_ = std::max(cell_, ext[a] / 256.0);
  }
  for (int a = 0; a < 3; ++a) n_[a] = count(a);
  lo_ = lo;
  counts_.assign(size_t(n_[0]) * n_[1] * n_[2], 0);
}

size_t DensityVolume::voxel(const glm::dvec3 &p) const {
  int i[3];
  for (int a = 0; a < 3; ++a) i[a] = std::clamp(int((p[a] - lo_[a]) / cell_), 0, n_[a] - 1);
  return (size_t(i[2]) * n_[1] + i[1]) * n_[0] + i[0];
}

void DensityVolume::cast(const ViewGeometry &g, double z0, double z1, double radius) {
  tile_ = std::max(1, (std::max(g.width, g.height) + kMaxRays - 1) / kMaxRays);
  tiles_x_ = (g.width + tile_ - 1) / tile_, tiles_y_ = (g.height + tile_ - 1) / tile_;
  z0_ = z0, dz_ = std::max(z1 - z0, 1e-9) / kBins;
  cum_.assign(size_t(tiles_x_) * tiles_y_ * (kBins + 1), 0.0f);
  const glm::dmat4 inv = glm::inverse(g.view);
  // One pixel's footprint (the tile's rays all count as its centre's) at view depth z: (z w)(z h)
  // in perspective, w h in orthographic, grown by the radius on each side: the particles whose
  // spheres a ray through it can hit.
  const double w = 2.0 / (g.width * g.sx), h = 2.0 / (g.height * g.sy);  // one pixel's
  const double voxel_volume = cell_ * cell_ * cell_;
  const double step = dz_ / kStepsPerBin;
  for (int ty = 0; ty < tiles_y_; ++ty)
    for (int tx = 0; tx < tiles_x_; ++tx) {
      // The ray through the tile's centre: world(z) = a + z b.
      const double px = std::min((tx + 0.5) * tile_, double(g.width));
      const double py = std::min((ty + 0.5) * tile_, double(g.height));
      const double nx = px / g.width * 2.0 - 1.0, ny = 1.0 - py / g.height * 2.0;
      glm::dvec3 a, b;
      if (g.orthographic) {
        a = glm::dvec3(inv * glm::dvec4((nx - g.tx) / g.sx, (ny - g.ty) / g.sy, 0.0, 1.0));
        b = glm::dvec3(inv * glm::dvec4(0.0, 0.0, -1.0, 0.0));
      } else {
        a = glm::dvec3(inv * glm::dvec4(0.0, 0.0, 0.0, 1.0));
        b = glm::dvec3(inv * glm::dvec4(nx / g.sx, ny / g.sy, -1.0, 0.0));
      }
      float *cum = cum_.data() + (size_t(ty) * tiles_x_ + tx) * (kBins + 1);
      // The depths where the ray is inside the grid (slab test): only those steps are marched.
      double za = z0, zb = z1;
      for (int ax = 0; ax < 3; ++ax) {
        const double top = lo_[ax] + n_[ax] * cell_;
        if (std::abs(b[ax]) < 1e-300) {
          if (a[ax] < lo_[ax] || a[ax] >= top) za = zb + 1.0;
          continue;
        }
        double t0 = (lo_[ax] - a[ax]) / b[ax], t1 = (top - a[ax]) / b[ax];
        if (t0 > t1) std::swap(t0, t1);
        za = std::max(za, t0), zb = std::min(zb, t1);
      }
      const int first = za < zb ? std::max(0, int((za - z0) / step)) : kBins * kStepsPerBin;
      const int last = za < zb ? std::min(kBins * kStepsPerBin - 1, int((zb - z0) / step)) : -1;
      double total = 0.0;
      for (int bin = 0; bin < kBins; ++bin) {
        for (int s = std::max(0, first - bin * kStepsPerBin);
             s < kStepsPerBin && bin * kStepsPerBin + s <= last; ++s) {
          const double z = z0 + (bin * kStepsPerBin + s + 0.5) * step;
          const glm::dvec3 p = a + z * b;
          int i[3];
          bool inside = true;
          for (int ax = 0; ax < 3; ++ax) {
            const double f = (p[ax] - lo_[ax]) / cell_;
            inside = inside && f >= 0.0 && f < n_[ax];
            i[ax] = inside ? int(f) : 0;
          }
          if (!inside) continue;
          const double count = counts_[(size_t(i[2]) * n_[1] + i[1]) * n_[0] + i[0]];
          const double area = g.orthographic ? (w + 2 * radius) * (h + 2 * radius)
                                             : (z * w + 2 * radius) * (z * h + 2 * radius);
          total += count / voxel_volume * area * step;
        }
        cum[bin + 1] = float(total);
      }
    }
}

}  // namespace lantern
