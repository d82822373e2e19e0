// LAMMPS's bonds as Lantern's lantern_bonds: the bonds of this rank's atoms as pairs of local
// indices into LAMMPS's x (owned atoms, then ghosts), with their bond type, and LAMMPS's ghosts
// after the owned atoms.
//
// Where the bonds come from. LAMMPS's own bond list (neighbor->bondlist, int [n][3]: atom, atom,
// type; the list its bond styles compute forces from) is borrowed in place, without a copy,
// whenever it holds every bond. It does not when a bond's type is turned off (negative: fix
// shake and fix rattle turn the types of the bonds they constrain negative, e.g. every O-H bond
// of rigid water), or when the script has no bond style (no list is built); LAMMPS's dump image
// still draws those bonds. Then the list is gathered from the atoms' own bond tables
// (atom->bond_atom, by global id) exactly as LAMMPS builds bondlist - the partner is the image
// closest to the owned atom (domain->closest_image) - into an index array this class owns: a
// copy of 12 bytes per bond, rebuilt at every callback.
//
// Which rank lists what follows newton_bond: on (LAMMPS's default), each bond is in one rank's
// list (LANTERN_BONDS_LISTED_ONCE); off, a bond between atoms of two ranks is in both
// (LANTERN_BONDS_LISTED_BY_BOTH). Either way images do not depend on the rank count.
//
// Ownership: the lantern_bonds filled in points into LAMMPS's arrays or into this object; both are
// valid until the next describe() (LAMMPS may rebuild bondlist when it reneighbours), so describe
// and publish at every callback. Thread-safety: LAMMPS's thread only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "lantern/lantern.h"

namespace lantern_lammps {

class BondList {
 public:
  enum class Source { kNone, kBorrowed, kGathered };

  // Fills *out with this rank's bonds of the LAMMPS instance `lmp` (count 0 for an atom style
  // without bonds). Returns "" or an error naming what is wrong.
  std::string describe(void *lmp, lantern_bonds *out);

  Source source() const { return source_; }  // of the last describe()
  // One line for the log: where the last describe() took the bonds from, e.g. "borrowed LAMMPS's
  // bond list (1365 bonds on rank 0)".
  std::string summary() const;

 private:
  Source source_ = Source::kNone;
  int64_t count_ = 0;
  std::vector<int> gathered_;  // [n][3]: atom, partner, type (kGathered)
};

}  // namespace lantern_lammps
