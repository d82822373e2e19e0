// The bonds of the current step, cut into half-bonds and grouped by brick: the unit in which
// bonds are culled and drawn.
//
// A bond is two half-bonds, each a cylinder from one atom's centre to the bond's midpoint
// (half_bond_end, core/particles/periodic_box.h). This rank keeps the halves it draws (the
// listing rule of lantern_bonds: every half of its list under kListedOnce, the halves of owned
// atoms under kListedByBoth) and files each under the brick of its owned atom - its own atom, or
// for a ghost's half under kListedOnce the bond's owned atom. Each brick then has the bounds of
// its halves' ends, which culling grows by the bond radius: a brick's bonds are culled with it.
// Inside a brick the halves follow the brick's order of their owned atoms, so the halves of one
// atom are consecutive: culling judges such a run at once, by a sphere round the atom that holds
// all of them (reach), before judging its halves one by one.
//
// Ownership: owns 12 bytes per half-bond, 8 per atom (reach) and a few dozen per brick; refers
// to atoms and bonds by index, so it is valid for the arrays and bricks it was built from (one
// step).
// Thread-safety: immutable after build; concurrent readers are fine.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/bricks/brick_set.h"
#include "core/common/status.h"
#include "core/particles/bond_arrays.h"
#include "core/particles/particle_arrays.h"
#include "core/particles/periodic_box.h"

namespace lantern {

// One half of a bond, drawn from `atom`'s centre towards `partner`, up to the bond's midpoint.
struct HalfBond {
  uint32_t atom;     // the half's atom: owned, or a ghost (kListedOnce)
  uint32_t partner;  // the bond's other atom
  uint32_t bond;     // the bond's index in the published list (for its type)
};

struct BrickBonds {
  std::vector<HalfBond> halves;  // brick after brick
  std::vector<uint32_t> first;   // halves of brick b: [first[b], first[b + 1]); bricks + 1 entries
  // Per brick: bounds of its halves' two ends (atom centre and midpoint end); lo > hi when it has
  // none. Units: the simulation's; add the bond radius to cull.
  std::vector<glm::dvec3> lo, hi;
  // Per atom index (owned and ghosts): the longest of its halves here (|midpoint end - centre|),
  // 0 for an atom without one. Units: the simulation's; add the bond radius to cull.
  std::vector<double> reach;
  int64_t bonds = 0;      // bonds in the published list
  int64_t skipped = 0;    // bonds left out for being invalid (first_error says why)
  int64_t ungrouped = 0;  // bonds left out because an atom is outside the group (mask)
  Status first_error;     // the first invalid bond (BondArrays::check_bond), else OK

  size_t half_count() const { return halves.size(); }
  uint32_t halves_of(size_t brick) const { return first[brick + 1] - first[brick]; }
};

// Working memory of build_brick_bonds, kept between steps so that a step's build allocates (and
// faults in) nothing new. Ownership: owns its vectors; one thread.
struct BrickBondsScratch {
  std::vector<HalfBond> unsorted;
  std::vector<uint32_t> slot_of, key, next;
};

// Builds the half-bonds of `bonds` for `bricks` (built from the same `particles`), with the
// minimum image of `box` (null: none). Invalid bonds are left out and the first is reported in
// out->first_error; so are bonds with an atom outside the group (mask). `scratch` (optional)
// lends working memory; *out's vectors are reused too.
void build_brick_bonds(const ParticleArrays &particles, const BondArrays &bonds,
                       const BrickSet &bricks, const PeriodicBox *box, BrickBonds *out,
                       BrickBondsScratch *scratch = nullptr);

// The step's BrickBonds, kept for every scene of a step: rebuilt when the bricks (their
// generation), the bond publication (`serial`, which the owner bumps on every publish) or the
// box changed. Ownership: owns its BrickBonds. Thread-safety: one thread.
class BondCache {
 public:
  const BrickBonds &for_step(const ParticleArrays &particles, const BondArrays &bonds,
                             uint64_t serial, const BrickSet &bricks, const PeriodicBox *box,
                             int64_t step, double *build_ms);
  // What for_step() at `step` found wrong with the bonds: OK when nothing, or when no scene
  // asked for them at that step.
  Status status(int64_t step) const {
    return used_ && step == step_ ? built_.first_error : Status();
  }
  // Forgets the bonds (and the status): the next for_step() builds afresh.
  void clear() { *this = BondCache(); }

 private:
  uint64_t generation_ = 0, serial_ = 0;
  int64_t step_ = 0;
  bool used_ = false, had_box_ = false;
  PeriodicBox box_;
  BrickBonds built_;
  BrickBondsScratch scratch_;
};

}  // namespace lantern
