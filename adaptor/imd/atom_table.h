// What IMD does not send: each atom's type and id. An IMD frame is bare coordinates in the
// server's order (LAMMPS's fix imd: its group's atoms sorted by atom ID; GROMACS: the IMD group's
// atoms in index order). lantern-imd reads types and ids from a file in the formats lantern-render
// reads (a LAMMPS text dump with `id type` columns, or an H5MD file): its first frame, sorted by
// id, gives the type and id of the stream's atom i. Without a file every atom has type 0 and id
// i + 1 (LAMMPS's IDs when they run 1..n).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lantern_imd {

struct AtomTable {
  std::vector<int32_t> type;
  std::vector<int64_t> id;
};

// The table for a stream of n atoms: from `path` (read on this process alone), or the default
// when `path` is empty. "" and *out, or an error naming the file (unreadable, no type column, a
// different atom count, repeated ids).
std::string load_atom_table(const std::string &path, int64_t n, AtomTable *out);

}  // namespace lantern_imd
