// The per-atom quantity lantern-lammps publishes as Lantern's scalar, named as LAMMPS names it in
// the YAML's `lammps: {scalar: ...}`:
//   c_ID      a per-atom vector compute (lammps_extract_compute, LMP_STYLE_ATOM/LMP_TYPE_VECTOR)
//   c_ID[N]   column N (1-based) of a per-atom array compute
//   v_name    an atom-style variable (lammps_extract_variable)
//   vx ... fz, x, y, z, or any per-atom double property LAMMPS has (q, rmass, radius, ...)
//
// Ownership: computes and properties are LAMMPS's own arrays, borrowed like x (never copied).
// An atom-style variable is the exception: LAMMPS evaluates it into a new array that the caller
// must free (lammps_free). PerAtomScalar owns that copy and frees it only after the next
// lantern_publish() has replaced it, because Lantern reads the published arrays until then.
// Thread-safety: one thread (LAMMPS's). Units: LAMMPS's.
#pragma once

#include <memory>
#include <set>
#include <string>

#include "lantern/lantern.h"

namespace lantern_lammps {

struct ScalarName {
  enum class Kind { kNone, kCompute, kVariable, kProperty } kind = Kind::kNone;
  std::string id;       // compute ID, variable name, or LAMMPS's per-atom array name
  int column = 0;       // c_ID[N]: N (1-based); 0 for a per-atom vector
  int component = -1;   // vx: 0 of "v"; -1 for a 1-D property
  std::string written;  // as the YAML wrote it, for messages
};

// Parses `text` ("" gives kNone). Returns "" or an error naming the text.
std::string parse_scalar_name(const std::string &text, ScalarName *out);

class PerAtomScalar {
 public:
  explicit PerAtomScalar(ScalarName name) : name_(std::move(name)) {}

  bool wanted() const { return name_.kind != ScalarName::Kind::kNone; }

  // Before a run: the compute, variable or property exists (and the variable is atom-style).
  // `atom_variables`: the atom-style variables the script defined. "" or an error.
  std::string check_known(void *lmp, const std::set<std::string> &atom_variables) const;

  // The current values of the nlocal owned atoms, into *out. `group` is the fix's group (an
  // atom-style variable is evaluated for its atoms). "" or an error naming the quantity.
  std::string extract(void *lmp, const std::string &group, int nlocal, lantern_array *out);

  // Call after lantern_publish(): frees the variable copy the previous publish used.
  void published();

 private:
  struct Free {
    void operator()(double *p) const;
  };
  using Copy = std::unique_ptr<double, Free>;

  std::string extract_compute(void *lmp, int nlocal, lantern_array *out) const;
  std::string extract_property(void *lmp, int nlocal, lantern_array *out) const;

  ScalarName name_;
  Copy published_;  // the variable copy Lantern reads now
  Copy next_;       // the copy of the publish under way
};

}  // namespace lantern_lammps
