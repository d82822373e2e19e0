#include "core/render/sphere_instances.h"

#include <algorithm>

#include "core/culling/draw_list.h"
#include "core/particles/particle_scan.h"
#include "core/particles/typed_access.h"
#include "core/render/screen_door.h"

namespace lantern {

Coloring make_coloring(const ColorConfig &config, const Extent &global) {
  Coloring c;
  c.by = config.by;
  c.solid = to_rgb8(config.solid);
  c.palette = TypePalette(config.palette);
  c.map = Colormap::choose(config.colormap, config.colormap_colors, config.reverse);
  if (config.range) {
    c.lo = (*config.range)[0];
    c.hi = (*config.range)[1];
  } else if (global.has_scalar_range()) {
    c.lo = global.scalar_min;
    c.hi = global.scalar_max;
  }
  return c;
}

InstanceRecipe make_recipe(const ParticleArrays &particles, const ShadingSettings &shading,
                           const RadiusRule &radius, const Camera &camera, const Extent &global) {
  InstanceRecipe r;
  r.particles = &particles;
  r.origin = camera.origin;
  r.per_particle_radius = radius.per_particle;
  r.radius = float(radius.radius);
  r.coloring = make_coloring(shading.color, global);
  // All opaque: no table, so alpha() costs one test (images without `opacity` are unchanged).
  const bool see_through = std::any_of(shading.opacity.begin(), shading.opacity.end(),
                                       [](double a) { return opacity_alpha8(a) < 255; });
  if (see_through)
    for (const double a : shading.opacity) r.alpha_by_type.push_back(opacity_alpha8(a));
  return r;
}

namespace {

// One instance from typed readers: the hot loop of every frame, so no per-element type switch
// for positions and radii (colors still go through the recipe: few branches, table lookups).
template <typename Positions, typename Radii>
SphereInstance make_instance(const InstanceRecipe &recipe, const Positions &pos,
                             const Radii &radius, int64_t i, float scale) {
  const glm::dvec3 p = pos.get(i) - recipe.origin;
  SphereInstance s;
  s.x = float(p.x);
  s.y = float(p.y);
  s.z = float(p.z);
  s.radius = float(radius.get(i)) * scale;
  const Rgb8 c = recipe.color(i);
  s.rgba[0] = c[0];
  s.rgba[1] = c[1];
  s.rgba[2] = c[2];
  s.rgba[3] = recipe.alpha(i);
  return s;
}

template <typename F>
void with_readers(const InstanceRecipe &recipe, F &&f) {
  const ParticleArrays &p = *recipe.particles;
  visit_positions(p, [&](const auto &pos) {
    visit_radii(p, recipe.per_particle_radius, recipe.radius,
                [&](const auto &radius) { f(pos, radius); });
  });
}

}  // namespace

void build_all_instances(const InstanceRecipe &recipe, std::vector<SphereInstance> *out) {
  const ParticleArrays &p = *recipe.particles;
  out->clear();
  out->reserve(size_t(p.count()));
  with_readers(recipe, [&](const auto &pos, const auto &radius) {
    visit_kept(p, [&](const auto &keep) {
      for (int64_t i = 0; i < p.count(); ++i)
        if (keep.get(i) && finite_position(pos.get(i)))
          out->push_back(make_instance(recipe, pos, radius, i, 1.0f));
    });
  });
}

void build_selected_instances(const InstanceRecipe &recipe, const PageVector<uint64_t> &entries,
                              std::vector<SphereInstance> *out) {
  out->resize(entries.size());
  with_readers(recipe, [&](const auto &pos, const auto &radius) {
    SphereInstance *dst = out->data();
    for (const uint64_t e : entries)
      *dst++ = make_instance(recipe, pos, radius, entry_index(e), entry_scale(e));
  });
}

}  // namespace lantern
