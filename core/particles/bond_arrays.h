// Typed, validated access to the bonds a simulation lends Lantern (BondDescription): pairs of
// indices into the published particle arrays, an optional bond type, and the ghosts after the
// owned particles that bonds may end at.
//
// Two checks: validate() the description (types, strides, counts, ghosts with ids) and then
// every bond (check_bond: indices in range, not an atom to itself, not two ghosts, finite ends),
// once when published and again per rendered step - the arrays are read in place and may change.
//
// Ownership: BondArrays never owns or copies; it stores pointers and strides, and refers to the
// particles by index. Thread-safety: read-only after construction.
#pragma once

#include <cstdint>
#include <string>

#include <glm/vec3.hpp>

#include "core/common/status.h"
#include "core/particles/bond_description.h"
#include "core/particles/particle_arrays.h"
#include "core/particles/particle_scan.h"

namespace lantern {

class BondArrays {
 public:
  BondArrays() = default;

  // Checks `d` against the particles it indexes (published before it): kInvalidArgument naming
  // the field at fault (e.g. "bonds.ghost_count: 12 ghosts without particle ids ..."), else OK
  // with *out filled. It reads no bond; check_bonds() does.
  static Status validate(const BondDescription &d, const ParticleArrays &particles,
                         BondArrays *out);

  int64_t count() const { return count_; }
  int64_t ghost_count() const { return ghost_count_; }
  BondListing listing() const { return listing_; }
  int64_t first(int64_t k) const { return first_.integer(k); }
  int64_t second(int64_t k) const { return second_.integer(k); }
  bool has_type() const { return type_.present(); }
  int64_t type(int64_t k) const { return type_.integer(k); }
  // Particles a bond may index: the owned ones, then the ghosts.
  int64_t reach(const ParticleArrays &particles) const { return particles.count() + ghost_count_; }

  // OK when bond k is drawable: both indices in [0, reach), distinct, not both ghosts, both
  // positions finite. Else kInvalidArgument naming the bond, e.g. "bonds.second[12]: 5000 is not
  // below count + ghost_count (4000 + 900)".
  Status check_bond(int64_t k, const ParticleArrays &particles) const;

  // check_bond's rule without the message, reading positions through `pos` (typed_access.h) for
  // particles.count() = owned: true when bond k is drawable, with its ends' positions in *x0
  // and *x1. The loops over every bond use it; check_bond words a bond it fails.
  template <typename Positions>
  bool drawable(int64_t k, int64_t owned, const Positions &pos, glm::dvec3 *x0,
                glm::dvec3 *x1) const {
    const int64_t e0 = first(k), e1 = second(k), end = owned + ghost_count_;
    if (!(e0 >= 0 && e0 < end && e1 >= 0 && e1 < end && e0 != e1 && (e0 < owned || e1 < owned)))
      return false;
    *x0 = pos.get(e0), *x1 = pos.get(e1);
    return finite_position(*x0) && finite_position(*x1);
  }

 private:
  int64_t count_ = 0, ghost_count_ = 0;
  BondListing listing_ = BondListing::kListedOnce;
  StridedArray first_, second_, type_;
};

// The first bad bond of `bonds` (check_bond), or OK: one pass over the list.
Status check_bonds(const BondArrays &bonds, const ParticleArrays &particles);

}  // namespace lantern
