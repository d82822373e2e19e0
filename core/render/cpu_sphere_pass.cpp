#include "core/render/cpu_sphere_pass.h"

#include <algorithm>

#include "core/particles/typed_access.h"

namespace lantern {
namespace {

// Pixels of slack around a sphere's outline for the CPU raster: its float per-pixel test errs by
// about 1e-4 px at most (column offsets of up to thousands of pixels times a float step).
constexpr double kRasterSlack = 0.05;

}  // namespace

CullStats CpuSpherePass::run(const ParticleArrays &particles, const BrickSet &bricks,
                             const SceneConfig &scene, const BrickSelection &sel,
                             const InstanceRecipe &recipe, const uint8_t background[4],
                             Frame *frame, DrawList *out) {
  CullStats st = sel.stats;
  out->clear();
  const ViewGeometry &g = sel.g;
  const bool occlusion = sel.mode == OcclusionMode::kHzb;
  const bool point_path = scene.lod.point_path;
  const bool two = split_strips(g.width, strips_);
  CpuSphereRaster::clear_target(g, background, frame);
  for (int k = 0; k < 2; ++k) {
    rasters_[k].begin_strip(g, frame, strips_[k].x0, strips_[k].x1);
    rasters_[k].set_lighting(scene.lighting);
  }

  const Frustum frustum(g);
  const CutPlanes cuts(scene.cuts);
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, sel.radius.per_particle, sel.radius.radius, [&](const auto &radius) {
      const CullPass<std::decay_t<decltype(pos)>, std::decay_t<decltype(radius)>> pass{
          pos, radius, g, frustum, cuts, scene, bricks};
      const auto strip = [&](int k) {
        CpuSphereRaster &raster = rasters_[k];
        const auto covered = [&raster](const PixelRect &r, double z) {
          return raster.covered(r, z);
        };
        const auto visit = [&](const Candidate &c, StripState *s) {
          if (point_path && splat_sized(g, c.c, c.r)) {
            s->out.points.push_back(draw_entry(c.index, c.scale));  // splatted after the raster
            return;
          }
          // The raster tests and casts exactly the pixels its per-pixel test can accept (up to
          // kRasterSlack), not sphere_rect's extra pixel that OpenGL's float rasterisation needs.
          PixelRect r = g.sphere_rect_tight(c.c, c.r, kRasterSlack);
          if (r.empty()) {  // covers no pixel centre: drawn, as OpenGL would, with nothing to cast
            s->out.spheres.push_back(draw_entry(c.index, c.scale));
            return;
          }
          r.x0 = std::max(r.x0, s->x0), r.x1 = std::min(r.x1, s->x1);
          if (r.empty() || (occlusion && raster.covered(r, -c.c.z - c.r - g.eps))) return;
          const Rgb8 color = recipe.color(c.index);
          raster.draw(c.c, c.r, color.data(), r, recipe.alpha(c.index));
          s->out.spheres.push_back(draw_entry(c.index, c.scale));
        };
        walk_strip(pass, sel.visible, occlusion, covered, visit, &strips_[k]);
      };
      run_strips(two, sel.visible, strip, strips_);
    });
  });
  // The merged lists are already in published order (draw_list.h).
  merge_strips(sel.visible, bricks, strips_, &scratch_, &st, out);
  std::vector<uint64_t>().swap(scratch_);  // per-frame scratch: keep nothing between frames
  st.drawn = int64_t(out->spheres.size());
  st.splatted = int64_t(out->points.size());
  return st;
}

}  // namespace lantern
