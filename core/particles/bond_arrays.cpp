#include "core/particles/bond_arrays.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "core/particles/particle_scan.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

Status invalid(std::string message) {
  return {StatusCode::kInvalidArgument, std::move(message)};
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

// "atom 12" or, with ids, "atom 12 (id 5012)": how a bond's end is named in messages.
std::string atom_name(const ParticleArrays &p, int64_t i) {
  std::string s = "atom " + std::to_string(i);
  if (p.has_id()) s += " (id " + std::to_string(p.id(i)) + ")";
  return s;
}

}  // namespace

Status BondArrays::validate(const BondDescription &d, const ParticleArrays &particles,
                            BondArrays *out) {
  if (d.count < 0) return invalid("bonds.count: negative (" + std::to_string(d.count) + ")");
  // Half-bonds are indexed with 32 bits, two per bond.
  if (d.count > std::numeric_limits<int32_t>::max())
    return invalid("bonds.count: " + std::to_string(d.count) + " is above 2^31 - 1 per rank");
  if (d.ghost_count < 0)
    return invalid("bonds.ghost_count: negative (" + std::to_string(d.ghost_count) + ")");
  // Compared without the sum, which a ghost_count near INT64_MAX overflowed (skipping the check).
  if (d.ghost_count > int64_t(std::numeric_limits<uint32_t>::max()) - particles.count())
    return invalid("bonds.ghost_count: count + ghost_count (" + std::to_string(particles.count()) +
                   " + " + std::to_string(d.ghost_count) + ") is not below 2^32");
  const int listing = static_cast<int>(d.listing);
  if (listing != static_cast<int>(BondListing::kListedOnce) &&
      listing != static_cast<int>(BondListing::kListedByBoth))
    return invalid("bonds.listing: " + std::to_string(listing) +
                   " is not LANTERN_BONDS_LISTED_ONCE (0) or LANTERN_BONDS_LISTED_BY_BOTH (1)");
  if (d.ghost_count > 0 && !particles.has_id())
    return invalid("bonds.ghost_count: " + std::to_string(d.ghost_count) +
                   " ghosts but no particle ids (lantern_particles.id): ghosts are named by "
                   "their global id, so publish the id array, covering the ghosts too");
  BondArrays b;
  b.count_ = d.count;
  b.ghost_count_ = d.ghost_count;
  b.listing_ = d.listing;
  const auto required = [&](const BorrowedArray &a, const char *name, StridedArray *to) -> Status {
    if (d.count > 0 && a.data == nullptr && a.type == DataType::kNone)
      return invalid(std::string("bonds.") + name + ": NULL with count > 0");
    return check_borrowed_array(a, std::string("bonds.") + name, 1, false, d.count, to);
  };
  if (Status s = required(d.first, "first", &b.first_); !s.ok()) return s;
  if (Status s = required(d.second, "second", &b.second_); !s.ok()) return s;
  if (Status s = check_borrowed_array(d.type, "bonds.type", 1, false, d.count, &b.type_); !s.ok())
    return s;
  *out = b;
  return {};
}

Status BondArrays::check_bond(int64_t k, const ParticleArrays &particles) const {
  const int64_t owned = particles.count(), end = reach(particles);
  const int64_t ends[2] = {first(k), second(k)};
  const bool in_range = ends[0] >= 0 && ends[0] < end && ends[1] >= 0 && ends[1] < end;
  // The common case costs a few compares and two position reads; messages are built only for
  // a bond at fault.
  if (in_range && ends[0] != ends[1] && (ends[0] < owned || ends[1] < owned) &&
      finite_position(particles.position(ends[0])) && finite_position(particles.position(ends[1])))
    return {};
  const char *names[2] = {"first", "second"};
  const std::string bond = "[" + std::to_string(k) + "]";
  for (int e = 0; e < 2; ++e) {
    const std::string field = std::string("bonds.") + names[e] + bond + ": ";
    if (ends[e] < 0) return invalid(field + std::to_string(ends[e]) + " is negative");
    if (ends[e] >= end)
      return invalid(field + std::to_string(ends[e]) + " is not below count + ghost_count (" +
                     std::to_string(owned) + " + " + std::to_string(ghost_count_) + ")");
  }
  if (ends[0] == ends[1])
    return invalid("bonds" + bond + ": joins " + atom_name(particles, ends[0]) + " to itself");
  if (ends[0] >= owned && ends[1] >= owned)
    return invalid("bonds" + bond + ": both atoms are ghosts (" + atom_name(particles, ends[0]) +
                   ", " + atom_name(particles, ends[1]) +
                   "); list a bond on a rank that owns one of its atoms");
  for (int e = 0; e < 2; ++e) {
    const glm::dvec3 x = particles.position(ends[e]);
    if (!finite_position(x))
      return invalid("bonds" + bond + ": " + atom_name(particles, ends[e]) + " (bonds." + names[e] +
                     ") is at (" + number(x.x) + ", " + number(x.y) + ", " + number(x.z) +
                     "), not a finite position");
  }
  return {};
}

Status check_bonds(const BondArrays &bonds, const ParticleArrays &particles) {
  // One typed pass for the common case (every bond drawable); from the first that is not,
  // check_bond words the error.
  int64_t first_bad = bonds.count();
  visit_positions(particles, [&](const auto &pos) {
    glm::dvec3 x0, x1;
    for (int64_t k = 0; k < bonds.count(); ++k)
      if (!bonds.drawable(k, particles.count(), pos, &x0, &x1)) {
        first_bad = k;
        return;
      }
  });
  for (int64_t k = first_bad; k < bonds.count(); ++k)
    if (Status s = bonds.check_bond(k, particles); !s.ok()) return s;
  return {};
}

}  // namespace lantern
