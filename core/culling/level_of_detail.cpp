#include "core/culling/level_of_detail.h"

#include <algorithm>
#include <cmath>

namespace lantern {
namespace {

// Mean particle spacing in a brick: the side of the cube each particle owns. A flat or thin
// brick gets at least the spacing implied by its largest side.
double spacing(const Brick &b) {
  const glm::dvec3 e = b.hi - b.lo;
  const double side = std::max({e.x, e.y, e.z});
  const double floor_len = side / std::max(1.0, std::cbrt(double(b.count)));
  const double v = std::max(e.x, floor_len) * std::max(e.y, floor_len) * std::max(e.z, floor_len);
  return b.count > 1 ? std::cbrt(v / b.count) : 0.0;
}

// How much a kept sphere grows when it stands for `ratio` (= n / keep) spheres of brick `v`.
float growth_of(LodGrowth growth, const ViewGeometry &g, const VisibleBrick &v, double ratio) {
  const double px = v.radius * g.pixels_per_unit(std::max(v.near_depth, g.near_plane));
  if (growth == LodGrowth::kCoverage && px < kCoveragePixels) return float(std::sqrt(ratio));
  return float(std::cbrt(ratio));
}

}  // namespace

bool apply_level_of_detail(const LodConfig &lod, const BrickSet &set, const ViewGeometry &g,
                           LodGrowth growth, std::vector<VisibleBrick> *visible) {
  int64_t total = 0;
  for (const VisibleBrick &v : *visible) total += set.bricks[v.brick].count;
  double share = std::min(1.0, lod.fraction);
  if (lod.budget > 0 && total > 0) share = std::min(share, double(lod.budget) / double(total));
  bool reduced = false;
  for (VisibleBrick &v : *visible) {
    const Brick &b = set.bricks[v.brick];
    double keep = double(b.count) * share;
    if (lod.min_pixels > 0.0) {
      const double px = spacing(b) * g.pixels_per_unit(std::max(v.near_depth, g.near_plane));
      if (px > 0.0 && px < lod.min_pixels)
        keep = std::min(keep, double(b.count) * std::pow(px / lod.min_pixels, 3.0));
    }
    const auto k = uint32_t(std::clamp(std::ceil(keep - 1e-9), 1.0, double(b.count)));
    v.keep = k;
    v.radius_scale = k < b.count ? growth_of(growth, g, v, double(b.count) / double(k)) : 1.0f;
    reduced |= k < b.count;
  }
  return reduced;
}

}  // namespace lantern
