#include "core/render/density_pass.h"

#include "core/culling/cut_planes.h"
#include "core/particles/typed_access.h"

namespace lantern {

void select_density_bricks(const BrickSet &bricks, const Camera &camera, const SceneConfig &scene,
                           const RadiusRule &radius, BrickSelection *out,
                           BrickCutCounts *cut_counts) {
  SceneConfig all = scene;
  all.culling.frustum = false;
  all.culling.occlusion = OcclusionMode::kNone;
  select_bricks(bricks, camera, all, radius, out, cut_counts);
}

int density_channels(ColorBy by) {
  return by == ColorBy::kSolid ? 1 : 4;
}

CullStats render_density(const ParticleArrays &particles, const BrickSet &bricks,
                         const SceneConfig &scene, const BrickSelection &sel,
                         const InstanceRecipe &recipe, DensityImage *image) {
  CullStats st = sel.stats;
  const ViewGeometry &g = sel.g;
  image->reset(g.width, g.height, density_channels(recipe.coloring.by));
  DensitySplatter splatter(g, image);
  const CutPlanes cuts(scene.cuts);
  const bool colored = image->channels > 1;
  const Rgb8 none{0, 0, 0};
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, sel.radius.per_particle, sel.radius.radius, [&](const auto &radius) {
      for (const VisibleBrick &v : sel.visible) {
        const Brick &b = bricks.bricks[v.brick];
        st.lod_dropped += int64_t(b.count) - int64_t(v.keep);
        // Each kept particle stands for count / keep of them (seed 001's brightness rule).
        const double weight = double(b.count) / double(v.keep);
        const uint32_t *index = bricks.order.data() + b.first;
        for (uint32_t k = 0; k < v.keep; ++k) {
          const uint32_t i = index[k];
          const glm::dvec3 x = pos.get(i);
          if (v.cut_each && cuts.drops(x)) {
            ++st.cut_culled;
            continue;
          }
          if (splatter.splat(g.to_view(x), radius.get(i), weight, colored ? recipe.color(i) : none))
            ++st.drawn;
          else
            ++st.frustum_culled;
        }
      }
    });
  });
  return st;
}

}  // namespace lantern
