#include "bond_list.h"

#include <cstdlib>

#include "lammps_internals.h"

namespace lantern_lammps {
namespace {

// A [n][3] int list (atom, partner, type) as lantern_bonds' three strided views.
void view_triples(const int *triples, int64_t count, lantern_bonds *out) {
  out->count = count;
  if (count == 0) return;
  constexpr int64_t kRow = 3 * sizeof(int);
  out->first = {triples, LANTERN_INT32, kRow};
  out->second = {triples + 1, LANTERN_INT32, kRow};
  out->type = {triples + 2, LANTERN_INT32, kRow};
}

// Whether any owned atom has a bond whose type is turned off (negative): those are missing from
// neighbor->bondlist.
bool has_turned_off_bonds(const LAMMPS_NS::Atom &atom) {
  for (int i = 0; i < atom.nlocal; ++i)
    for (int m = 0; m < atom.num_bond[i]; ++m)
      if (atom.bond_type[i][m] < 0) return true;
  return false;
}

}  // namespace

std::string BondList::describe(void *handle, lantern_bonds *out) {
  auto *lmp = static_cast<LAMMPS_NS::LAMMPS *>(handle);
  LAMMPS_NS::Atom &atom = *lmp->atom;
  *out = lantern_bonds{};
  count_ = 0;
  source_ = Source::kNone;
  if (!atom.molecular || !atom.num_bond || !atom.bond_atom) return "";  // no bonds in this style
  // A rank without atoms lists no bonds, and publishes no arrays its ghosts could follow.
  if (atom.nlocal == 0) return "";
  out->ghost_count = atom.nghost;
  const bool newton_bond = lmp->force->newton_bond != 0;
  out->listing = newton_bond ? LANTERN_BONDS_LISTED_ONCE : LANTERN_BONDS_LISTED_BY_BOTH;

  if (lmp->force->bond && !has_turned_off_bonds(atom)) {
    const LAMMPS_NS::Neighbor &neighbor = *lmp->neighbor;
    source_ = Source::kBorrowed;
    count_ = neighbor.nbondlist;
    view_triples(count_ > 0 ? neighbor.bondlist[0] : nullptr, count_, out);
    return "";
  }

  // As LAMMPS's Neighbor builds bondlist (ntopo_bond_all), but keeping turned-off bonds.
  source_ = Source::kGathered;
  gathered_.clear();
  const int nlocal = atom.nlocal;
  for (int i = 0; i < nlocal; ++i) {
    for (int m = 0; m < atom.num_bond[i]; ++m) {
      const int type = atom.bond_type[i][m];
      if (type == 0) continue;  // a deleted bond (delete_bonds ... remove keeps type 0)
      const int partner = atom.map(atom.bond_atom[i][m]);
      if (partner < 0)
        return "bond of atom " + std::to_string(atom.tag[i]) + " to atom " +
               std::to_string(atom.bond_atom[i][m]) +
               ", which this rank does not hold (a bond longer than the ghost cutoff: raise "
               "comm_modify cutoff)";
      const int j = lmp->domain->closest_image(i, partner);
      if (!newton_bond && j < i) continue;  // both owned: listed from the lower index only
      gathered_.insert(gathered_.end(), {i, j, std::abs(type)});
    }
  }
  count_ = int64_t(gathered_.size() / 3);
  view_triples(gathered_.data(), count_, out);
  return "";
}

std::string BondList::summary() const {
  const std::string n = std::to_string(count_) + " bonds on rank 0";
  switch (source_) {
    case Source::kBorrowed:
      return "bonds: LAMMPS's own bond list, borrowed (" + n + ")";
    case Source::kGathered:
      return "bonds: gathered from the atoms' bond tables, since LAMMPS's bond list leaves out "
             "turned-off bonds (fix shake/rattle) or has no bond style (" +
             n + ")";
    case Source::kNone:
      break;
  }
  return "bonds: none (the atom style has no bonds)";
}

}  // namespace lantern_lammps
