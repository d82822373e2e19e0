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
#include <limits>
#include <type_traits>
#include <utility>
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
// How many halves of an atom's run visit_bond_brick prepares before testing them (the network
// of tests/bench/lammps_dump_image_bonds.sh has 6 per atom).
inline constexpr uint32_t kBondBatch = 8;

// Whether an occlusion test has warm(rect): a hint that it will be asked about rect soon.
template <typename Hidden, typename = void>
inline constexpr bool kWarms = false;
template <typename Hidden>
inline constexpr bool
    kWarms<Hidden, std::void_t<decltype(std::declval<const Hidden &>().warm(PixelRect()))>> = true;

// Every half of visible brick k of `sel` that survives the cutting planes and the frustum:
// hidden(rect, depth) is asked for the brick and then each half (true: every pixel of rect holds
// something nearer than depth, so it is dropped as occluded); visit(view) gets the others.
// Records the brick's drops in *drops (begin_bond_drops); `pos` reads the particle positions
// (core/particles/typed_access.h); `frustum` is that of g. A `hidden` with a member
// warm(rect) is told of each rectangle some time before it is asked about it (to prefetch).
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
  // The halves' atoms lie scattered in the positions (and the atoms' reach): each is asked for
  // kBondPrefetch halves ahead of its use (only a hint to the cache); the partners a few runs
  // ahead of theirs.
  uint32_t ahead = bonds.first[v.brick];
  // The run of halves of one atom (brick_bonds.h): they share its cut and, when the sphere round
  // the atom that holds them all (its reach plus the bond radius) is hidden, their fate.
  struct Run {
    uint32_t begin, end;
    bool cut;
    glm::dvec3 atom, centre;
    double reach = 0.0;  // of the sphere round the halves, when there are two or more
    PixelRect rect;
  };
  // The brick's runs are prepared first (atom, cut, view position, sphere), then judged and drawn
  // nearest first - by their atom's depth, in kRunBins bins over the brick's depth range - so
  // that nearer halves are in the depth before farther ones are asked about: more of those are
  // then found hidden before any pixel work (on the bonded-network bench a third fewer halves
  // are drawn). The image does not depend on the order (cpu_sphere_raster.h). The lists are
  // per thread and kept between calls (a few kilobytes per thousand runs).
  thread_local std::vector<Run> prepared;
  thread_local std::vector<uint32_t> order;
  prepared.clear();
  const uint32_t begin = bonds.first[v.brick];
  double near = std::numeric_limits<double>::infinity(), far = -near;
  for (uint32_t h = begin; h < end;) {
    const uint32_t atom_index = bonds.halves[h].atom;
    uint32_t run_end = h + 1;
    while (run_end < end && bonds.halves[run_end].atom == atom_index) ++run_end;
    for (const uint32_t to = std::min(end, run_end + kBondPrefetch); ahead < to; ++ahead) {
      const HalfBond &next = bonds.halves[ahead];
      pos.prefetch(next.atom);
      __builtin_prefetch(bonds.reach.data() + next.atom, 0, 3);
    }
    Run run;
    run.begin = h, run.end = run_end;
    run.atom = pos.get(atom_index);
    run.cut = v.cut_each && cuts.drops(run.atom);
    h = run_end;
    if (run.cut) {
      cut_culled += run.end - run.begin;
      continue;
    }
    run.centre = g.to_view(run.atom);
    if (run_end - run.begin > 1) {
      // sphere_rect holds every pixel OpenGL could give the halves, as cylinder_rect does.
      run.reach = bonds.reach[atom_index] + sel.radius + g.eps;
      run.rect = g.sphere_rect(run.centre, run.reach);
    }
    near = std::min(near, -run.centre.z), far = std::max(far, -run.centre.z);
    prepared.push_back(run);
  }
  // Counting sort by depth bin (stable: the halves' order within a bin).
  constexpr int kRunBins = 64;
  uint32_t first_of[kRunBins + 1] = {};
  const double scale = far > near ? (kRunBins - 1) / (far - near) : 0.0;
  const auto bin_of = [&](const Run &run) {
    const double t = (-run.centre.z - near) * scale;
    return t >= 0.0 && t < kRunBins ? int(t) : t >= kRunBins ? kRunBins - 1 : 0;
  };
  for (const Run &run : prepared) ++first_of[bin_of(run) + 1];
  for (int b = 0; b < kRunBins; ++b) first_of[b + 1] += first_of[b];
  order.resize(prepared.size());
  for (uint32_t i = 0; i < prepared.size(); ++i) order[first_of[bin_of(prepared[i])]++] = i;
  uint32_t partner_ahead = 0;  // into order: runs whose partners were asked for
  for (uint32_t next_run = 0; next_run < order.size(); ++next_run) {
    for (const uint32_t to = std::min(uint32_t(order.size()), next_run + 3); partner_ahead < to;
         ++partner_ahead) {
      const Run &next = prepared[order[partner_ahead]];
      for (uint32_t h = next.begin; h < next.end; ++h) pos.prefetch(bonds.halves[h].partner);
      if constexpr (kWarms<Hidden>)
        if (next.end - next.begin > 1) hidden.warm(next.rect);
    }
    const Run &run = prepared[order[next_run]];
    if (run.end - run.begin > 1 && !run.rect.empty() &&
        hidden(run.rect, -run.centre.z - run.reach - g.eps))
      continue;  // occluded, every one
    // The run's halves a batch at a time: first every half's ends and rectangle - independent
    // of one another and of the depth, so their divisions and square roots overlap - then the
    // occlusion tests and draws in order.
    for (uint32_t h = run.begin; h < run.end;) {
      HalfBondView views[kBondBatch];
      int n = 0;
      for (const uint32_t batch_end = std::min(run.end, h + kBondBatch); h < batch_end; ++h) {
        HalfBondView &view = views[n];
        view.index = h;
        view.a = run.centre;
        view.b = g.to_view(half_bond_end(run.atom, pos.get(bonds.halves[h].partner), box));
        if (straddle) {  // the half's bounding sphere
          const glm::dvec3 mid = 0.5 * (view.a + view.b);
          const double half_reach = 0.5 * glm::length(view.b - view.a) + sel.radius;
          if (frustum.classify_sphere(mid, half_reach) == Containment::kOutside) {
            ++frustum_culled;
            continue;
          }
        }
        view.rect = cylinder_rect(g, view.a, view.b, sel.radius, &view.near_depth);
        ++n;
      }
      if constexpr (kWarms<Hidden>)
        for (int j = 0; j < n; ++j) hidden.warm(views[j].rect);
      for (int j = 0; j < n; ++j)
        if (!views[j].rect.empty() && !hidden(views[j].rect, views[j].near_depth)) visit(views[j]);
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
