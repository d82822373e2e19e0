#include "core/render/bond_instances.h"

#include "core/particles/typed_access.h"

namespace lantern {

BondRecipe make_bond_recipe(const InstanceRecipe &atoms, const ShadingSettings &shading,
                            const BondArrays &bonds, const BrickBonds &halves,
                            const PeriodicBox *box, double radius) {
  BondRecipe r;
  r.atoms = &atoms;
  r.bonds = &bonds;
  r.halves = &halves;
  r.box = box;
  r.by = shading.bonds.color;
  r.solid = to_rgb8(shading.bonds.solid);
  r.palette = TypePalette(shading.bonds.palette);
  r.radius = float(radius);
  return r;
}

void build_bond_instances(const BondRecipe &recipe, const std::vector<uint32_t> &kept,
                          std::vector<BondInstance> *out) {
  out->resize(kept.size());
  const glm::dvec3 origin = recipe.atoms->origin;
  visit_positions(*recipe.atoms->particles, [&](const auto &pos) {
    BondInstance *dst = out->data();
    for (const uint32_t k : kept) {
      const HalfBond &h = recipe.halves->halves[k];
      const glm::dvec3 atom = pos.get(h.atom);
      const glm::dvec3 start = atom - origin;
      const glm::dvec3 end = half_bond_end(atom, pos.get(h.partner), recipe.box) - origin;
      BondInstance &b = *dst++;
      b.start[0] = float(start.x), b.start[1] = float(start.y), b.start[2] = float(start.z);
      b.end[0] = float(end.x), b.end[1] = float(end.y), b.end[2] = float(end.z);
      b.radius = recipe.radius;
      const Rgb8 c = recipe.color(h);
      b.rgba[0] = c[0], b.rgba[1] = c[1], b.rgba[2] = c[2], b.rgba[3] = recipe.alpha(h);
    }
  });
}

}  // namespace lantern
