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
// step, or later ones after refit_brick_bonds when neither the list nor the bricks' order changed).
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

// Refits `out`, built by build_brick_bonds for the same bond list and bricks of the same
// order_generation, to the particles' current positions: the halves and their grouping stay, the
// bricks' bounds and the atoms' reach are recomputed from the positions, bit for bit what a build
// gives. False - *out then stale, to be rebuilt - when a position is not finite (the build words
// that bond) or a bound is exactly zero (-0 and +0 depend on the order the ends are met in).
bool refit_brick_bonds(const ParticleArrays &particles, const BondArrays &bonds,
                       const BrickSet &bricks, const PeriodicBox *box, BrickBonds *out);

// The step's BrickBonds, kept for every scene of a step and between steps: within a step,
// rebuilt when the bricks (their generation), the bond publication (`serial`, which the owner
// bumps on every publish) or the box changed. On a later step the grouping (which halves, filed
// under which brick, in which order) is kept and only refit (refit_brick_bonds) when it cannot
// have changed: bricks of the same order_generation (no particle changed slot), the same box,
// owned and ghost counts and listing, no group (mask), no bond left out, and every bond's two
// indices the same as last step - compared in full with a copy, because hosts rewrite their list
// in place at the same address (LAMMPS at every re-neighbouring). Else it is built afresh.
// Ownership: owns its BrickBonds and the copy of the indices (8 bytes per bond). Thread-safety:
// one thread.
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
  // Whether the last for_step() served its step with a refit of an earlier step's grouping.
  bool reused() const { return reused_; }
  int64_t reuses() const { return reuses_; }  // steps served by a refit instead of a build
  // Forgets the bonds (and the status): the next for_step() builds afresh.
  void clear() { *this = BondCache(); }

 private:
  // Compares the list's indices with last step's copy and updates the copy: true when the same.
  bool same_indices(const BondArrays &bonds);
  bool can_refit(const ParticleArrays &particles, const BondArrays &bonds, const BrickSet &bricks,
                 const PeriodicBox *box, bool indices_same) const;

  uint64_t generation_ = 0, serial_ = 0, order_generation_ = 0;
  int64_t step_ = 0, owned_ = -1, ghosts_ = -1, reuses_ = 0;
  BondListing listing_ = BondListing::kListedOnce;
  bool used_ = false, had_box_ = false, reused_ = false;
  PeriodicBox box_;
  BrickBonds built_;
  BrickBondsScratch scratch_;
  std::vector<uint32_t> indices_;  // last step's first and second of every bond, interleaved
  bool indices_valid_ = false;     // indices_ holds a whole list (every index below 2^32)
};

}  // namespace lantern
