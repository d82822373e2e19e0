// Ibrahim et al.'s particle density volume (§4.4): particle counts on a coarse regular grid over
// the bounds of the particles still considered, and per-pixel density histograms D(t) cast through
// it (eq. 9-10), kept as cumulative counts per depth bin for RayDensity (depth_confidence.h).
//
// Rank-local by design: this rank samples and culls only its own particles, so the counts that
// enter eqs. 5 and 11-22 (N nearer particles, B(d) behind, p) must be of its own particles;
// counts of other ranks' particles would claim occlusion this rank can neither observe nor use.
// Integer counts per voxel; a meshlet moving to the occluded class removes its particles
// (the dynamic update of §4.4).
//
// Histograms are cast for at most kMaxRays x kMaxRays rays, one per tile of T x T pixels
// (T = 1 up to 128^2 images); every pixel of a tile reads the counts of the ray through its centre.
// Units: world lengths for the grid, view depths for the bins.
// Thread-safety: none; one culling pass owns it.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/culling/probabilistic/depth_confidence.h"
#include "core/view/view_geometry.h"

namespace lantern {

class DensityVolume {
 public:
  static constexpr int kMaxRays = 128;
  static constexpr int kBins = 32;

  // An empty grid over [lo, hi] with about `particles` / 8 voxels (at most 64^3), cubic cells.
  void reset(const glm::dvec3 &lo, const glm::dvec3 &hi, int64_t particles);
  void add(const glm::dvec3 &p) { ++counts_[voxel(p)]; }
  void remove(const glm::dvec3 &p) {
    int32_t &c = counts_[voxel(p)];
    c -= c > 0;
  }

  // Casts every tile's ray of the image of `g` through the grid between view depths z0 < z1,
  // counting the particles of spheres of `radius` that the tile's rays can hit (centres within
  // `radius` of its footprint; Ibrahim et al. assume sub-pixel particles, where that is the
  // footprint).
  void cast(const ViewGeometry &g, double z0, double z1, double radius);
  // D(t) of pixel (x, y) from the last cast.
  RayDensity ray(int x, int y) const {
    const int tx = x / tile_, ty = y / tile_;
    return {cum_.data() + (size_t(ty) * tiles_x_ + tx) * (kBins + 1), kBins, z0_, dz_, scale_};
  }

 private:
  size_t voxel(const glm::dvec3 &p) const;

  glm::dvec3 lo_{0.0};
  double cell_ = 1.0;
  int n_[3] = {1, 1, 1};
  std::vector<int32_t> counts_;
  int tile_ = 1, tiles_x_ = 1, tiles_y_ = 1;
  double z0_ = 0.0, dz_ = 1.0, scale_ = 1.0;
  std::vector<float> cum_;  // per tile: kBins + 1 cumulative counts
};

}  // namespace lantern
