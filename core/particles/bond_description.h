// How a simulation describes the bonds it lends Lantern: two borrowed index arrays into the
// published particle arrays, an optional bond type, the number of ghost particles after the
// owned ones, and how the ranks' lists share the bonds out. Core's own vocabulary for the C API's
// lantern_bonds (adaptor/ translates one to the other field by field).
//
// Ownership: a description borrows; whoever fills it keeps the arrays alive (see BondArrays).
#pragma once

#include <cstdint>

#include "core/particles/particle_description.h"

namespace lantern {

// Which rank draws which half of a bond (lantern_bond_listing; the values are the C API's).
// Fixed underlying type: a C caller may store any int, and validation names it.
enum class BondListing : int {
  kListedOnce = 0,    // each bond on one rank, which draws both halves
  kListedByBoth = 1,  // on both atoms' ranks; each draws the halves of the atoms it owns
};

struct BondDescription {
  int64_t count = 0;
  BorrowedArray first, second;  // int32/int64 indices into the particle arrays
  BorrowedArray type;           // optional int32/int64 bond type
  int64_t ghost_count = 0;      // particle entries count .. count + ghost_count - 1 are ghosts
  BondListing listing = BondListing::kListedOnce;
};

}  // namespace lantern
