#include "core/pipeline/sphere_instances.h"

#include "core/pipeline/particle_scan.h"

namespace lantern {

Colouring make_colouring(const ColorConfig &config, const Extent &global) {
  Colouring c;
  c.by = config.by;
  c.solid = to_rgb8(config.solid);
  c.palette = TypePalette(config.palette);
  if (auto map = Colormap::named(config.colormap)) c.map = *map;
  if (config.range) {
    c.lo = (*config.range)[0];
    c.hi = (*config.range)[1];
  } else if (global.has_scalar_range()) {
    c.lo = global.scalar_min;
    c.hi = global.scalar_max;
  }
  return c;
}

InstanceRecipe make_recipe(const ParticleArrays &particles, const SceneConfig &scene,
                           const Camera &camera, const Extent &global) {
  InstanceRecipe r;
  r.particles = &particles;
  r.origin = camera.origin;
  r.per_particle_radius = scene.per_particle_radius && particles.has_radius();
  r.radius = float(scene.radius);
  r.colouring = make_colouring(scene.color, global);
  return r;
}

void build_all_instances(const InstanceRecipe &recipe, std::vector<SphereInstance> *out) {
  const ParticleArrays &p = *recipe.particles;
  out->clear();
  out->reserve(size_t(p.count()));
  for (int64_t i = 0; i < p.count(); ++i)
    if (finite_position(p.position(i))) out->push_back(recipe.make(i));
}

}  // namespace lantern
