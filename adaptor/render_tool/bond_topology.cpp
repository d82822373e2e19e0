#include "bond_topology.h"

#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <unordered_map>

namespace lantern {
namespace {

std::string without_comment(const std::string &line) {
  const size_t hash = line.find('#');
  return hash == std::string::npos ? line : line.substr(0, hash);
}

bool blank(const std::string &line) {
  return line.find_first_not_of(" \t\r") == std::string::npos;
}

// Appends row `r` of `all` to `out`, its position replaced by `x`.
void copy_row(const ParticleFrame &all, int64_t r, const double x[3], ParticleFrame *out) {
  out->position.insert(out->position.end(), {x[0], x[1], x[2]});
  if (!all.type.empty()) out->type.push_back(all.type[size_t(r)]);
  out->id.push_back(all.id[size_t(r)]);
  if (!all.scalar.empty()) out->scalar.push_back(all.scalar[size_t(r)]);
  if (!all.radius.empty()) out->radius.push_back(all.radius[size_t(r)]);
}

// A `dump local` of bonds: per step, the rows of its ITEM: ENTRIES.
std::string read_dump_local(std::istream &in, const std::string &path, BondSource *out) {
  out->per_step = true;
  std::string line;
  int64_t number = 0, step = -1;
  auto where = [&]() { return path + ":" + std::to_string(number) + ": "; };
  while (std::getline(in, line)) {
    ++number;
    if (line.rfind("ITEM: TIMESTEP", 0) == 0) {
      if (!std::getline(in, line)) return where() + "file ends after ITEM: TIMESTEP";
      ++number;
      step = std::stoll(line);
      out->by_step[step];  // a step may have no bonds
      continue;
    }
    if (line.rfind("ITEM: ENTRIES", 0) != 0) continue;  // NUMBER OF ENTRIES, BOX BOUNDS, ...
    if (step < 0) return where() + "ITEM: ENTRIES before ITEM: TIMESTEP";
    std::istringstream names(line.substr(std::string("ITEM: ENTRIES").size()));
    std::vector<int> columns;  // the atom-id columns, then the type's, skipping `index`
    std::string name;
    for (int k = 0; names >> name; ++k)
      if (name != "index") columns.push_back(k);
    if (columns.size() < 2)
      return where() +
             "a dump local of bonds needs two atom-id columns (c_ID[1] c_ID[2] of "
             "compute property/local batom1 batom2)";
    BondTopology &bonds = out->by_step[step];
    while (in.peek() != 'I' && std::getline(in, line)) {
      ++number;
      if (blank(line)) continue;
      std::istringstream words(line);
      std::vector<double> v;
      for (double x; words >> x;) v.push_back(x);
      if (v.size() <= size_t(columns[1]))
        return where() + "short line: " + std::to_string(v.size()) + " columns";
      bonds.first_id.push_back(int64_t(v[size_t(columns[0])]));
      bonds.second_id.push_back(int64_t(v[size_t(columns[1])]));
      bonds.type.push_back(
          columns.size() > 2 && v.size() > size_t(columns[2]) ? int64_t(v[size_t(columns[2])]) : 0);
    }
  }
  if (out->by_step.empty()) return path + ": no ITEM: TIMESTEP (not a LAMMPS dump local)";
  return {};
}

std::string read_data_file(std::istream &in, const std::string &path, BondTopology *out) {
  std::string line;
  int64_t declared = -1, number = 0;
  // The header: "N bonds"; then sections, each a title line, a blank line and its rows.
  while (std::getline(in, line)) {
    ++number;
    std::istringstream words(without_comment(line));
    std::string first, second;
    words >> first >> second;
    if (second == "bonds" && number > 1) declared = std::stoll(first);
    if (first == "Bonds" && second.empty()) break;
  }
  if (!in) return path + ": no 'Bonds' section (is it a LAMMPS data file of a molecular system?)";
  while (std::getline(in, line)) {
    ++number;
    const std::string text = without_comment(line);
    if (blank(text)) {
      if (!out->first_id.empty()) break;  // the blank line after the section
      continue;
    }
    std::istringstream words(text);
    int64_t id = 0, type = 0, a = 0, b = 0;
    if (!(words >> id >> type >> a >> b))
      return path + ":" + std::to_string(number) +
             ": a Bonds line must be 'bond-id type atom-id atom-id'";
    out->first_id.push_back(a);
    out->second_id.push_back(b);
    out->type.push_back(type);
  }
  if (declared >= 0 && declared != int64_t(out->first_id.size()))
    return path + ": the header declares " + std::to_string(declared) +
           " bonds, the Bonds section has " + std::to_string(out->first_id.size());
  return {};
}

}  // namespace

const BondTopology *BondSource::at(int64_t step) const {
  if (!per_step) return &fixed;
  const auto found = by_step.find(step);
  return found == by_step.end() ? nullptr : &found->second;
}

std::string read_bond_source(const std::string &path, BondSource *out) {
  std::ifstream in(path);
  if (!in) return path + ": cannot read the bond file";
  *out = BondSource{};
  std::string first;
  while (std::getline(in, first) && blank(first)) {
  }
  in.clear();
  in.seekg(0);
  try {
    if (first.rfind("ITEM: TIMESTEP", 0) == 0) return read_dump_local(in, path, out);
    return read_data_file(in, path, &out->fixed);
  } catch (const std::exception &) {  // std::stoll on a malformed number
    return path + ": not a LAMMPS data file or dump local (a number could not be read)";
  }
}

std::string rows_of_ids(const ParticleFrame &all, const std::vector<int64_t> &ids,
                        std::vector<int64_t> *rows) {
  if (all.id.size() != size_t(all.count()))
    return "bonds need the atom ids of the dump (dump custom ... id ...)";
  std::unordered_map<int64_t, int64_t> row_of;
  row_of.reserve(all.id.size());
  for (size_t r = 0; r < all.id.size(); ++r) row_of.emplace(all.id[r], int64_t(r));
  rows->clear();
  rows->reserve(ids.size());
  for (const int64_t id : ids) {
    const auto r = row_of.find(id);
    if (r == row_of.end()) return "atom id " + std::to_string(id) + " is not in the frame";
    rows->push_back(r->second);
  }
  return {};
}

namespace {

// The image of the atom at `b` closest to the atom at `a` in a triclinic box, as LAMMPS finds and
// makes it: whole periodic images k along c, then b, then a (Domain::minimum_image's order), the
// ghost at b + (ka lx + kb xy + kc xz, kb ly + kc yz, kc lz) as its border communication
// shifts a coordinate. *xb the image, key[1..3] = (ka, kb, kc).
void closest_triclinic_image(const Box &box, const double *a, const double *b, double *xb,
                             std::array<int64_t, 4> *key) {
  const auto l = box.edges();
  const double xy = box.tilt[0], xz = box.tilt[1], yz = box.tilt[2];
  double k[3] = {0, 0, 0};  // along a, b, c
  const auto whole = [&](int axis, double separation) {
    if (!box.periodic[size_t(axis)]) return 0.0;
    const double n = std::nearbyint(separation / l[size_t(axis)]);
    // NaN (a NaN coordinate, a zero-length axis) or beyond int64: no image (the bond's NaN end
    // is refused by the publish, naming it); the conversion would be undefined.
    return std::abs(n) < 9e18 ? n : 0.0;
  };
  k[2] = whole(2, a[2] - b[2]);
  k[1] = whole(1, a[1] - (b[1] + k[2] * yz));
  k[0] = whole(0, a[0] - (b[0] + (k[1] * xy + k[2] * xz)));
  const double shift[3] = {k[0] * l[0] + k[1] * xy + k[2] * xz, k[1] * l[1] + k[2] * yz,
                           k[2] * l[2]};
  for (int axis = 0; axis < 3; ++axis) {
    xb[axis] = k[0] == 0 && k[1] == 0 && k[2] == 0 ? b[axis] : b[axis] + shift[axis];
    (*key)[size_t(axis + 1)] = int64_t(k[axis]);
  }
}

}  // namespace

std::string share_with_bonds(const ParticleFrame &all, const std::vector<int64_t> &rows,
                             const BondTopology &topology, BondedShare *out) {
  if (all.id.empty()) return "bonds need the atom ids of the dump (dump custom ... id ...)";
  *out = BondedShare{};
  out->frame.step = all.step, out->frame.time = all.time, out->frame.box = all.box;
  out->frame.global_count = all.global_count;
  std::unordered_map<int64_t, int64_t> row_of;
  row_of.reserve(all.id.size());
  for (size_t r = 0; r < all.id.size(); ++r) row_of.emplace(all.id[r], int64_t(r));
  std::vector<int64_t> local_of(size_t(all.count()), -1);  // whole-frame row -> this rank's row
  for (size_t j = 0; j < rows.size(); ++j) {
    const int64_t r = rows[j];
    if (r < 0 || r >= all.count() || local_of[size_t(r)] >= 0)
      return "row " + std::to_string(r) + " is not a row of the frame, or given twice";
    local_of[size_t(r)] = int64_t(j);
    copy_row(all, r, &all.position[size_t(3 * r)], &out->frame);
  }
  out->owned = int64_t(rows.size());

  std::map<std::array<int64_t, 4>, int64_t> ghost_of;  // (row, image shift per axis) -> local row
  for (size_t k = 0; k < topology.first_id.size(); ++k) {
    const auto a = row_of.find(topology.first_id[k]), b = row_of.find(topology.second_id[k]);
    if (a == row_of.end() || b == row_of.end()) {
      if (!topology.origin.empty())
        return topology.origin + "[" +
               std::to_string(k < topology.pair.size() ? topology.pair[k] : int64_t(k)) +
               "]: particle id " +
               std::to_string(a == row_of.end() ? topology.first_id[k] : topology.second_id[k]) +
               " is not in the frame";
      ++out->skipped;
      continue;
    }
    if (local_of[size_t(a->second)] < 0) continue;  // another rank's bond
    const double *xa = &all.position[size_t(3 * a->second)];
    double xb[3];
    std::array<int64_t, 4> key{b->second, 0, 0, 0};
    if (all.box && all.box->triclinic)
      closest_triclinic_image(*all.box, xa, &all.position[size_t(3 * b->second)], xb, &key);
    for (int axis = 0; axis < 3 && !(all.box && all.box->triclinic); ++axis) {
      xb[axis] = all.position[size_t(3 * b->second + axis)];
      if (!all.box || !all.box->periodic[size_t(axis)]) continue;
      const double length = all.box->high[size_t(axis)] - all.box->low[size_t(axis)];
      double shift = std::nearbyint((xa[axis] - xb[axis]) / length);
      // NaN (a NaN coordinate, a zero-length axis) or beyond int64: no image (the bond's NaN end
      // is refused by the publish, naming it); the conversion would be undefined.
      if (!(std::abs(shift) < 9e18)) shift = 0.0;
      key[size_t(axis + 1)] = int64_t(shift);
      if (shift != 0.0) xb[axis] += shift * length;  // the closest image, as LAMMPS's ghost
    }
    int64_t partner = 0;
    const bool plain = key[1] == 0 && key[2] == 0 && key[3] == 0;
    if (plain && local_of[size_t(b->second)] >= 0) {
      partner = local_of[size_t(b->second)];
    } else if (const auto g = ghost_of.find(key); g != ghost_of.end()) {
      partner = g->second;
    } else {
      partner = out->frame.count();
      copy_row(all, b->second, xb, &out->frame);
      ghost_of.emplace(key, partner);
    }
    out->first.push_back(local_of[size_t(a->second)]);
    out->second.push_back(partner);
    out->type.push_back(topology.type[k]);
  }
  return {};
}

}  // namespace lantern
