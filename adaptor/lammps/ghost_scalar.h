// The scalar lantern-lammps publishes, extended to LAMMPS's ghost atoms for half-bonds colored
// by their atom (bonds: {color: by_atom} with color.by: scalar).
//
// Lantern reads the scalar of every bond end, ghosts included (entries nlocal .. nlocal + nghost
// of the published array: lantern.h, lantern_bonds.ghost_count). LAMMPS communicates positions,
// types and ids to ghosts, but not the values of computes, atom-style variables or most
// properties (velocities only with `comm_modify vel yes`): there a ghost's row holds a stale
// value or nothing at all. So the owned values are copied into an array of nlocal + nghost rows,
// and LAMMPS's own forward communication (Comm::forward_comm_array, the swaps that made the
// ghosts) fills the ghosts' rows from their owners: a ghost gets exactly its owner's value, the
// colour its atom's sphere has. A copy of 8 bytes an atom and one forward communication per
// rendered step, paid only where bonds and a scalar are both drawn.
//
// Ownership: the array given out is this object's, valid until the next extend() but one (two
// buffers alternate, so the array Lantern was last given stays intact until lantern_publish()
// replaces it). Thread-safety: LAMMPS's thread only. Units: the scalar's own.
#pragma once

#include <vector>

#include "lantern/lantern.h"

namespace lantern_lammps {

class GhostScalar {
 public:
  // `owned`: the nlocal owned atoms' values (LANTERN_FLOAT64, any stride; empty when nlocal is
  // 0). Sets *out to the nlocal + nghost values (empty when nlocal is 0). Collective over
  // LAMMPS's ranks: every rank calls it at the same callback, with or without atoms.
  void extend(void *lmp, lantern_array owned, lantern_array *out);

 private:
  std::vector<double> values_[2];
  std::vector<double *> rows_;  // forward_comm_array's [n][1] rows into the buffer being filled
  int next_ = 0;                // the buffer the next extend() fills
};

}  // namespace lantern_lammps
