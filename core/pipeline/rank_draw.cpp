#include "core/pipeline/rank_draw.h"

#include <array>
#include <chrono>
#include <cstdint>

#include "core/color/colormap.h"
#include "core/common/ms_since.h"
#include "core/particles/typed_access.h"
#include "core/pipeline/renderer_choice.h"
#include "core/render/bond_instances.h"
#include "core/render/point_splats.h"
#include "core/render/shading_settings.h"
#include "core/render/sphere_instances.h"

namespace lantern {

Status draw_scene_on_rank(const RankScene &in, RankDrawScratch *scratch, Frame *frame,
                          RankDraw *out) {
  using Clock = std::chrono::steady_clock;
  const CullSettings &cull = in.settings.cull;
  const ShadingSettings &shading = in.settings.shading;
  const Camera &camera = *in.camera;
  const ParticleArrays &particles = *in.particles;
  *out = RankDraw();
  // Only the CPU raster's pass says where it drew (OpenGL's readback and the splats do not).
  frame->drawn_within.reset();
  // Bricks, culling and level of detail: what to draw.
  auto t0 = Clock::now();
  BrickSelection &selection = scratch->selection;
  DrawList &draw = scratch->draw;
  select_bricks(*in.bricks, camera, cull, in.radius, &selection, in.cut_counts);
  InstanceRecipe recipe = make_recipe(particles, shading, in.radius, camera, in.global);
  recipe.occlusion = in.occlusion;
  const std::array<uint8_t, 4> clear = background_rgba8(shading);
  const uint8_t *background = clear.data();
  const bool cpu = draws_on_cpu(in.settings.renderer, in.settings.finish.height, camera,
                                in.radius.max_radius(in.global), in.renderer != nullptr,
                                !recipe.alpha_by_type.empty(), &selection);
  out->renderer = cpu ? "cpu" : "opengl";
  // Bonds: the bricks whose half-bonds the camera may see, and their colors.
  const bool bonds = cull.bonds && in.bond_halves && in.bond_halves->half_count() > 0;
  BondRecipe bond_recipe;
  BondDrawing bond_drawing;
  if (bonds) {
    select_bond_bricks(*in.bricks, *in.bond_halves, selection, cull, &scratch->bond_selection);
    bond_recipe =
        make_bond_recipe(recipe, shading, *in.bonds, *in.bond_halves, in.box, cull.bond_radius);
    bond_drawing = {&scratch->bond_selection, &bond_recipe};
  }
  out->cull = cpu ? scratch->cpu_pass.run(particles, *in.bricks, cull, shading.lighting, selection,
                                          recipe, background, frame, &draw, in.step, in.threads,
                                          bonds ? &bond_drawing : nullptr)
                  : scratch->culler.cull(particles, *in.bricks, cull, selection, &draw, in.threads);
  if (bonds && !cpu) {
    // After the spheres: their hzb, if any, proves half-bonds hidden exactly.
    std::vector<uint32_t> &kept = scratch->bond_kept;
    kept.clear();
    const Culler &culler = scratch->culler;
    const auto hidden = [&culler](const PixelRect &r, double z) { return culler.covered(r, z); };
    BondDrops drops;
    const CutPlanes cuts(cull.cuts);
    visit_positions(particles, [&](const auto &pos) {
      visit_bond_halves(
          *in.bond_halves, scratch->bond_selection, pos, in.box, selection.g, cuts, hidden,
          [&kept](const HalfBondView &v) { kept.push_back(v.index); }, &drops);
    });
    const BondDrops *passes[1] = {&drops};
    out->cull.bonds =
        bond_counts(*in.bond_halves, scratch->bond_selection, passes, 1, int64_t(kept.size()));
  }
  out->cull_ms = ms_since(t0);

  Status drawn;
  if (!cpu) {
    t0 = Clock::now();
    if (draw.everything)
      build_all_instances(recipe, &scratch->instances);
    else
      build_selected_instances(recipe, draw.spheres, &scratch->instances);
    PageVector<uint64_t>().swap(draw.spheres);  // only the instances outlive this point
    if (bonds) {
      build_bond_instances(bond_recipe, scratch->bond_kept, &scratch->bond_instances);
      std::vector<uint32_t>().swap(scratch->bond_kept);
    }
    out->instances_ms = ms_since(t0);
    RenderTimings timings;
    RenderView view = camera.render_view(background);
    view.lighting = shading.lighting;
    const size_t bond_count = bonds ? scratch->bond_instances.size() : 0;
    drawn = in.renderer->render(view, scratch->instances.data(), scratch->instances.size(),
                                scratch->bond_instances.data(), bond_count, frame, &timings);
    out->draw_ms = timings.draw_ms;
    out->readback_ms = timings.readback_ms;
  }
  if (!draw.points.empty()) {
    t0 = Clock::now();
    splat_points(
        particles, recipe.per_particle_radius, recipe.radius, draw.points, selection.g,
        [&recipe](int64_t i) { return recipe.color(i); }, frame,
        recipe.alpha_by_type.empty() ? AlphaOf()
                                     : AlphaOf([&recipe](int64_t i) { return recipe.alpha(i); }),
        shading.lighting);
    PageVector<uint64_t>().swap(draw.points);
    frame->drawn_within.reset();  // splats anywhere
    out->draw_ms += ms_since(t0);
  }
  return drawn;
}

}  // namespace lantern
