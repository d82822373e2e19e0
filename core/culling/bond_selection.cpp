#include "core/culling/bond_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lantern {

void select_bond_bricks(const BrickSet &bricks, const BrickBonds &bonds,
                        const BrickSelection &spheres, const CullSettings &cull,
                        BondSelection *out) {
  BondSelection &sel = *out;
  sel.visible.clear();
  sel.counts = BondCounts();
  sel.counts.halves = int64_t(bonds.half_count());
  sel.radius = cull.bond_radius;
  const ViewGeometry &g = spheres.g;
  const double r = sel.radius;
  // Bricks that level of detail thinned keep no bonds.
  std::vector<bool> thinned;
  if (spheres.reduced) {
    thinned.assign(bonds.lo.size(), false);
    for (const VisibleBrick &v : spheres.visible)
      if (v.nearest || v.radius_scale != 1.0f || v.keep < bricks.bricks[v.brick].count)
        thinned[v.brick] = true;
  }
  // The near depth of each brick whose particles are drawn (draw_depth).
  std::vector<double> particles_depth(bonds.lo.size(), std::numeric_limits<double>::quiet_NaN());
  for (const VisibleBrick &v : spheres.visible)
    if (v.brick < particles_depth.size()) particles_depth[v.brick] = v.near_depth;
  const Frustum frustum(g);
  const CutPlanes cuts(cull.cuts);
  for (uint32_t b = 0; b < bonds.lo.size(); ++b) {
    const uint32_t halves = bonds.halves_of(b);
    if (halves == 0) continue;
    if (!thinned.empty() && thinned[b]) {
      sel.counts.lod_dropped += halves;
      continue;
    }
    BondBrick v;
    v.brick = b;
    glm::dvec3 corners[8];
    box_corners(bonds.lo[b], bonds.hi[b], corners);
    for (glm::dvec3 &c : corners) c = g.to_view(c);
    if (cull.frustum) {
      v.containment = frustum.classify_box(corners, r);
      if (v.containment == Containment::kOutside) {
        sel.counts.frustum_culled += halves;
        continue;
      }
    }
    if (!cuts.empty()) {
      // The halves' atoms lie within the bounds of their ends.
      const CutPlanes::Side side = cuts.classify_box(bonds.lo[b], bonds.hi[b]);
      if (side == CutPlanes::Side::kDropped) {
        sel.counts.cut_culled += halves;
        continue;
      }
      v.cut_each = side == CutPlanes::Side::kBoth;
    }
    double nearest = std::numeric_limits<double>::infinity();
    for (const glm::dvec3 &c : corners) nearest = std::min(nearest, ViewGeometry::depth_of(c));
    v.near_depth = nearest - r - g.eps;
    v.draw_depth = std::isnan(particles_depth[b]) ? v.near_depth : particles_depth[b];
    box_corners(bonds.lo[b] - r, bonds.hi[b] + r, corners);
    for (glm::dvec3 &c : corners) c = g.to_view(c);
    v.rect = g.box_rect(corners);
    sel.visible.push_back(v);
  }
  std::stable_sort(
      sel.visible.begin(), sel.visible.end(),
      [](const BondBrick &a, const BondBrick &b) { return a.draw_depth < b.draw_depth; });
}

BondCounts bond_counts(const BrickBonds &bonds, const BondSelection &sel,
                       const BondDrops *const passes[], int pass_count, int64_t drawn) {
  BondCounts c = sel.counts;
  int64_t judged = 0;
  for (size_t k = 0; k < sel.visible.size(); ++k) {
    const int64_t halves = bonds.halves_of(sel.visible[k].brick);
    const BondDrops *by = nullptr;
    for (int p = 0; p < pass_count && !by; ++p)
      if (k < passes[p]->frustum.size() && passes[p]->frustum[k] >= 0) by = passes[p];
    if (!by) {
      c.occlusion_culled += halves;
      continue;
    }
    c.frustum_culled += by->frustum[k];
    c.cut_culled += by->cut[k];
    judged += halves - by->frustum[k] - by->cut[k];
  }
  c.occlusion_culled += judged - drawn;
  c.drawn = drawn;
  return c;
}

}  // namespace lantern
