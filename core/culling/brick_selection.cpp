#include "core/culling/brick_selection.h"

#include <algorithm>
#include <limits>

#include "core/config/enum_names.h"
#include "core/culling/cut_planes.h"
#include "core/culling/frustum.h"
#include "core/culling/level_of_detail.h"
#include "core/culling/occlusion_estimate.h"

namespace lantern {
namespace {

glm::dvec3 box_corner(const glm::dvec3 &lo, const glm::dvec3 &hi, int k) {
  return {k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z};
}

// A length bounding |x - origin| for every sphere and the eye: the scale of float rounding.
double scene_scale(const BrickSet &set, const Camera &camera, double max_radius) {
  double s = 0.0;
  for (int k = 0; k < 8; ++k)
    s = std::max(s, glm::length(box_corner(set.lo, set.hi, k) - camera.origin));
  return s + max_radius;
}

// Screen rectangle and nearest depth of a brick whose spheres have radius <= r.
void footprint(const ViewGeometry &g, const Brick &b, double r, VisibleBrick *v) {
  glm::dvec3 grown[8];
  double nearest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 8; ++k) {
    nearest = std::min(nearest, ViewGeometry::depth_of(g.to_view(box_corner(b.lo, b.hi, k))));
    grown[k] = g.to_view(box_corner(b.lo - r, b.hi + r, k));
  }
  v->near_depth = nearest - r - g.eps;
  v->rect = g.box_rect(grown);
}

// Frustum and cutting planes, brick by brick: the survivors with their footprints. The planes'
// verdicts come from `cut_counts` when given (already updated), else from the planes.
void classify(const BrickSet &bricks, const CullSettings &cull, const BrickCutCounts *cut_counts,
              BrickSelection *sel) {
  const ViewGeometry &g = sel->g;
  const Frustum frustum(g);
  const CutPlanes cuts(cull.cuts);
  const bool any_cut = cut_counts ? cut_counts->any_plane() : !cuts.empty();
  CullStats &st = sel->stats;
  for (uint32_t i = 0; i < bricks.bricks.size(); ++i) {
    const Brick &b = bricks.bricks[i];
    const double r = sel->radius.per_particle ? b.max_radius : sel->radius.radius;
    VisibleBrick v;
    v.brick = i;
    v.radius = r;
    v.keep = b.count;
    if (cull.frustum) {
      glm::dvec3 corners[8];
      for (int k = 0; k < 8; ++k) corners[k] = g.to_view(box_corner(b.lo, b.hi, k));
      v.containment = frustum.classify_box(corners, r);
      if (v.containment == Containment::kOutside) {
        ++st.bricks_outside;
        st.frustum_culled += b.count;
        continue;
      }
    }
    if (any_cut) {
      const CutPlanes::Side side = cut_counts ? cut_counts->side(i) : cuts.classify_box(b.lo, b.hi);
      if (side == CutPlanes::Side::kDropped) {
        st.cut_culled += b.count;
        continue;
      }
      v.cut_each = side == CutPlanes::Side::kBoth;
    }
    if (v.containment == Containment::kInside) ++st.bricks_inside;
    st.per_particle_frustum |= v.containment == Containment::kStraddling;
    footprint(g, b, r, &v);
    sel->visible.push_back(v);
  }
}

// The configured occlusion mode, or under auto the one choose_occlusion picks; bricks front to
// back for every mode that judges particles by depth.
void resolve_occlusion(const CullSettings &cull, BrickSelection *sel) {
  const auto front_to_back = [](const VisibleBrick &a, const VisibleBrick &b) {
    return a.near_depth < b.near_depth;
  };
  CullStats &st = sel->stats;
  sel->mode = cull.occlusion;
  if (sel->mode == OcclusionMode::kAuto) {
    std::stable_sort(sel->visible.begin(), sel->visible.end(), front_to_back);
    const OcclusionChoice choice = choose_occlusion(sel->visible, sel->g);
    sel->mode = choice.mode;
    st.occlusion = std::string(name_of(sel->mode)) + " (auto: " + choice.reason +
                   (st.per_particle_frustum ? "" : "; all in view, no per-particle frustum") + ")";
  } else {
    st.occlusion = name_of(sel->mode);
    if (sel->mode != OcclusionMode::kNone)
      std::stable_sort(sel->visible.begin(), sel->visible.end(), front_to_back);
  }
}

}  // namespace

void select_bricks(const BrickSet &bricks, const Camera &camera, const CullSettings &cull,
                   const RadiusRule &radius, BrickSelection *out) {
  select_bricks(bricks, camera, cull, radius, out, nullptr);
}

void select_bricks(const BrickSet &bricks, const Camera &camera, const CullSettings &cull,
                   const RadiusRule &radius, BrickSelection *out, BrickCutCounts *cut_counts) {
  if (cut_counts) cut_counts->update(bricks, cull.cuts);
  out->visible.clear();
  out->stats = CullStats();
  out->stats.candidates = bricks.particle_count();
  out->stats.bricks = int64_t(bricks.bricks.size());
  out->radius = radius;
  double max_r = radius.per_particle ? 0.0 : radius.radius;
  if (radius.per_particle)
    for (const Brick &b : bricks.bricks) max_r = std::max(max_r, b.max_radius);
  out->g = ViewGeometry::from_camera(camera, scene_scale(bricks, camera, max_r));
  classify(bricks, cull, cut_counts, out);

  // Level of detail, then footprints of the bricks whose spheres grew.
  const LodConfig &lod = cull.lod;
  const bool lod_on = lod.budget > 0 || lod.fraction < 1.0 || lod.min_pixels > 0.0;
  out->reduced = lod_on && apply_level_of_detail(lod, bricks, out->g, cull.lod_growth,
                                                 cull.lod_nearest, &out->visible);
  for (VisibleBrick &v : out->visible)
    if (v.radius_scale != 1.0f)
      footprint(out->g, bricks.bricks[v.brick], v.radius * v.radius_scale, &v);
  resolve_occlusion(cull, out);
}

}  // namespace lantern
