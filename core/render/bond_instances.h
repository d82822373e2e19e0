// How a scene colors its half-bonds, and the half-bonds the culling kept turned into the OpenGL
// renderer's BondInstances. The CPU pass asks the same recipe for each half's color and opacity,
// so both renderers color a bond alike.
//
// A half takes the opacity of its atom's type (a half-bond goes with its atom) and, under
// object-space ambient occlusion, the darkening at its atom's position.
// Ownership: a BondRecipe borrows the particle recipe, bonds and half-bonds it names for as long
// as it is used. Thread-safety: read-only; concurrent readers are fine.
#pragma once

#include <cstdint>
#include <vector>

#include "core/bricks/brick_bonds.h"
#include "core/color/colormap.h"
#include "core/particles/bond_arrays.h"
#include "core/particles/periodic_box.h"
#include "core/render/gl/sphere_renderer.h"
#include "core/render/shading_settings.h"
#include "core/render/sphere_instances.h"

namespace lantern {

struct BondRecipe {
  const InstanceRecipe *atoms = nullptr;  // the scene's particle colors, opacity, origin
  const BondArrays *bonds = nullptr;
  const BrickBonds *halves = nullptr;
  const PeriodicBox *box = nullptr;  // minimum image, or none
  BondColorBy by = BondColorBy::kAtom;
  Rgb8 solid{153, 153, 153};
  TypePalette palette{{}};
  float radius = 0.15f;

  Rgb8 color(const HalfBond &h) const {
    if (by == BondColorBy::kAtom) return atoms->color(h.atom);  // with its occlusion, if any
    const Rgb8 c =
        by == BondColorBy::kType ? palette.at(bonds->has_type() ? bonds->type(h.bond) : 0) : solid;
    if (!atoms->occlusion) return c;
    const float f = atoms->occlusion->factor(atoms->particles->position(h.atom));
    return {uint8_t(float(c[0]) * f + 0.5f), uint8_t(float(c[1]) * f + 0.5f),
            uint8_t(float(c[2]) * f + 0.5f)};
  }
  uint8_t alpha(const HalfBond &h) const { return atoms->alpha(h.atom); }
};

// The scene's bond colors (`shading.bonds`) at `radius`, for the half-bonds `halves` of `bonds`,
// with the particles' own colors from `atoms`.
BondRecipe make_bond_recipe(const InstanceRecipe &atoms, const ShadingSettings &shading,
                            const BondArrays &bonds, const BrickBonds &halves,
                            const PeriodicBox *box, double radius);

// Instances of the half-bonds `kept` (indices into recipe.halves->halves), in that order.
void build_bond_instances(const BondRecipe &recipe, const std::vector<uint32_t> &kept,
                          std::vector<BondInstance> *out);

}  // namespace lantern
