// Culling of half-bonds (core/bricks/brick_bonds.h), the bonds' counterpart of brick_selection.h
// and cull_pass.h: first brick by brick - the bounds of a brick's halves grown by the bond radius
// against the frustum and the cutting planes, their screen footprint and nearest depth - then half
// by half in the bricks that need it, with an occlusion test the caller supplies.
//
// Every test is conservative, so the exact modes stay exact: a half is dropped only when it lies
// wholly outside the frustum, its atom's centre is on the dropped side of a cutting plane (a half
// goes with its atom), or the caller's depth proves every pixel it could touch nearer. Level of
// detail: a brick that level of detail thins (it keeps fewer particles, or grows them) draws none
// of its bonds - they would end at dropped atoms or inside grown ones.
//
// Ownership: a BondSelection owns its vector (reused between frames) and refers to bricks by
// index. Thread-safety: visit_bond_halves only reads; run it from any number of threads.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/bricks/brick_bonds.h"
#include "core/culling/brick_selection.h"
#include "core/culling/cull_settings.h"
#include "core/culling/cull_stats.h"
#include "core/culling/cut_planes.h"
#include "core/culling/frustum.h"
#include "core/particles/periodic_box.h"
#include "core/view/cylinder_bounds.h"
#include "core/view/view_geometry.h"

namespace lantern {

// A brick whose half-bonds may be seen.
struct BondBrick {
  uint32_t brick = 0;
  Containment containment = Containment::kInside;  // kStraddling: test each half
  bool cut_each = false;    // some half's atom may lie on the dropped side of a cutting plane
  double near_depth = 0.0;  // nearest view depth any of its halves reaches
  // Where a renderer drawing bonds among the particles' bricks front to back draws this brick's
  // halves: just after the brick's own particles when they are drawn (the near depth of their
  // brick), so that an atom, drawn first, hides its halves' hidden parts; else near_depth.
  double draw_depth = 0.0;
  PixelRect rect;  // pixels its halves may touch
};

struct BondSelection {
  std::vector<BondBrick> visible;  // front to back (by draw_depth)
  double radius = 0.15;            // bonds.radius
  BondCounts counts;               // so far: halves, and the brick-level drops
};

// The bricks of `bonds` (made for `bricks`) the camera of `spheres` may see, for a scene culled
// by `cull` (whose level of detail `spheres` applied: its thinned bricks draw no bonds).
void select_bond_bricks(const BrickSet &bricks, const BrickBonds &bonds,
                        const BrickSelection &spheres, const CullSettings &cull,
                        BondSelection *out);

// One half-bond in view space, ready to test or draw.
struct HalfBondView {
  uint32_t index;     // into BrickBonds::halves
  glm::dvec3 a, b;    // view-space ends: the atom's centre, then the midpoint end
  PixelRect rect;     // every pixel whose centre it could cover
  double near_depth;  // its nearest view depth, less the tolerance
};

// Per visible bond brick of a pass: its halves dropped by the frustum and by the cutting planes,
// or -1 (both) where the pass's occlusion test skipped the whole brick.
struct BondDrops {
  std::vector<int64_t> frustum, cut;
};

// Sizes *drops for the visible bricks of `sel`, none judged yet (-1).
inline void begin_bond_drops(const BondSelection &sel, BondDrops *drops) {
  drops->frustum.assign(sel.visible.size(), -1);
  drops->cut.assign(sel.visible.size(), -1);
}

// How many half-bonds ahead visit_bond_brick prefetches their atoms' and partners' positions:
// about two atoms' runs, enough to cover a miss to memory at the cost of judging a run.
inline constexpr uint32_t kBondPrefetch = 12;

// Every half of visible brick k of `sel` that survives the cutting planes and the frustum:
// hidden(rect, depth) is asked for the brick and then each half (true: every pixel of rect holds
// something nearer than depth, so it is dropped as occluded); visit(view) gets the others.
// Records the brick's drops in *drops (begin_bond_drops); `pos` reads the particle positions
// (core/particles/typed_access.h); `frustum` is that of g.
template <typename Positions, typename Hidden, typename Visit>
void visit_bond_brick(size_t k, const BrickBonds &bonds, const BondSelection &sel,
                      const Positions &pos, const PeriodicBox *box, const ViewGeometry &g,
                      const Frustum &frustum, const CutPlanes &cuts, const Hidden &hidden,
                      const Visit &visit, BondDrops *drops) {
  const BondBrick &v = sel.visible[k];
  if (hidden(v.rect, v.near_depth)) return;
  int64_t frustum_culled = 0, cut_culled = 0;
  const bool straddle = v.containment == Containment::kStraddling;
  const uint32_t end = bonds.first[v.brick + 1];
  // The halves' atoms and partners lie scattered in the positions (and the atoms' reach): each
  // is asked for kBondPrefetch halves ahead of its use (only a hint to the cache).
  uint32_t ahead = bonds.first[v.brick];
  for (uint32_t h = bonds.first[v.brick]; h < end;) {
    // The run of halves of one atom (brick_bonds.h): they share its cut and, when the sphere
    // round the atom that holds them all (its reach plus the bond radius) is hidden, their fate.
    const uint32_t atom_index = bonds.halves[h].atom;
    uint32_t run_end = h + 1;
    while (run_end < end && bonds.halves[run_end].atom == atom_index) ++run_end;
    for (const uint32_t to = std::min(end, run_end + kBondPrefetch); ahead < to; ++ahead) {
      const HalfBond &next = bonds.halves[ahead];
      pos.prefetch(next.atom);
      pos.prefetch(next.partner);
      __builtin_prefetch(bonds.reach.data() + next.atom, 0, 3);
    }
    const glm::dvec3 atom = pos.get(atom_index);
    if (v.cut_each && cuts.drops(atom)) {
      cut_culled += run_end - h;
      h = run_end;
      continue;
    }
    const glm::dvec3 centre = g.to_view(atom);
    if (run_end - h > 1) {
      // sphere_rect holds every pixel OpenGL could give the halves, as cylinder_rect does.
      const double reach = bonds.reach[atom_index] + sel.radius + g.eps;
      const PixelRect rect = g.sphere_rect(centre, reach);
      if (!rect.empty() && hidden(rect, -centre.z - reach - g.eps)) {
        h = run_end;  // occluded, every one
        continue;
      }
    }
    for (; h < run_end; ++h) {
      HalfBondView view;
      view.index = h;
      view.a = centre;
      view.b = g.to_view(half_bond_end(atom, pos.get(bonds.halves[h].partner), box));
      if (straddle) {  // the half's bounding sphere
        const glm::dvec3 mid = 0.5 * (view.a + view.b);
        const double half_reach = 0.5 * glm::length(view.b - view.a) + sel.radius;
        if (frustum.classify_sphere(mid, half_reach) == Containment::kOutside) {
          ++frustum_culled;
          continue;
        }
      }
      view.rect = cylinder_rect(g, view.a, view.b, sel.radius, &view.near_depth);
      if (!view.rect.empty() && !hidden(view.rect, view.near_depth)) visit(view);
    }
  }
  drops->frustum[k] = frustum_culled;
  drops->cut[k] = cut_culled;
}

// visit_bond_brick for every visible brick of `sel`, front to back.
template <typename Positions, typename Hidden, typename Visit>
void visit_bond_halves(const BrickBonds &bonds, const BondSelection &sel, const Positions &pos,
                       const PeriodicBox *box, const ViewGeometry &g, const CutPlanes &cuts,
                       const Hidden &hidden, const Visit &visit, BondDrops *drops) {
  const Frustum frustum(g);
  begin_bond_drops(sel, drops);
  for (size_t k = 0; k < sel.visible.size(); ++k)
    visit_bond_brick(k, bonds, sel, pos, box, g, frustum, cuts, hidden, visit, drops);
}

// The counts of a selection's pass over `bonds`: the brick-level ones of `sel`, the drops of the
// first of `passes` (one, or two column strips: column_strips.h) that judged each brick - both
// drop the same halves of a brick they judge - and `drawn` halves; what is left was occluded.
BondCounts bond_counts(const BrickBonds &bonds, const BondSelection &sel,
                       const BondDrops *const passes[], int pass_count, int64_t drawn);

}  // namespace lantern
