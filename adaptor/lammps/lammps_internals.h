// LAMMPS's C++ classes (Atom, Comm, Neighbor, Force, Domain), for what its C library interface
// does not give in this version: the bond list and the atoms' bond tables (bond_list.h), and the
// forward communication that gives ghost atoms their owners' scalar (ghost_scalar.h).
//
// Debian's LAMMPS headers (2022) were written against the fmt library LAMMPS bundles (version 8),
// whose fmt::make_args_checked Debian's libfmt-dev (version 9) no longer has. Only template
// bodies that lantern-lammps never instantiates (Error::all, utils::logmesg) name it, so a
// declaration with the same meaning lets the headers compile; nothing here calls into fmt.
#pragma once

#include <fmt/format.h>

#if FMT_VERSION >= 90000
namespace fmt {
template <typename... Args, typename S>
auto make_args_checked(const S &, const std::remove_reference_t<Args> &...args) {
  return fmt::make_format_args(args...);
}
}  // namespace fmt
#endif

#include <lammps/atom.h>
#include <lammps/comm.h>
#include <lammps/domain.h>
#include <lammps/force.h>
#include <lammps/lammps.h>
#include <lammps/neighbor.h>
