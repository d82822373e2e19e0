// The C API's types <-> core's: field by field, pointers and strides only (never the particle
// data itself). Core has its own vocabulary (core/common/status.h,
// core/particles/particle_description.h) so that it never includes the public header; this file
// is where the two meet. The enums share numeric values, checked at compile time below.
#pragma once

#include <cstring>
#include <type_traits>

#include "core/common/status.h"
#include "core/particles/bond_description.h"
#include "core/particles/particle_description.h"
#include "lantern/lantern.h"

namespace lantern {

static_assert(int(StatusCode::kOk) == LANTERN_OK &&
                  int(StatusCode::kInternal) == LANTERN_ERR_INTERNAL &&
                  int(StatusCode::kNullArgument) == LANTERN_ERR_NULL_ARGUMENT &&
                  int(StatusCode::kInvalidArgument) == LANTERN_ERR_INVALID_ARGUMENT &&
                  int(StatusCode::kConfig) == LANTERN_ERR_CONFIG &&
                  int(StatusCode::kIo) == LANTERN_ERR_IO &&
                  int(StatusCode::kGl) == LANTERN_ERR_GL &&
                  int(StatusCode::kMpi) == LANTERN_ERR_MPI &&
                  int(StatusCode::kOutOfMemory) == LANTERN_ERR_OUT_OF_MEMORY,
              "StatusCode and lantern_status must keep the same values");
static_assert(int(DataType::kNone) == LANTERN_TYPE_NONE &&
                  int(DataType::kFloat32) == LANTERN_FLOAT32 &&
                  int(DataType::kFloat64) == LANTERN_FLOAT64 &&
                  int(DataType::kInt32) == LANTERN_INT32 && int(DataType::kInt64) == LANTERN_INT64,
              "DataType and lantern_datatype must keep the same values");

inline lantern_status to_c(StatusCode code) {
  return static_cast<lantern_status>(code);
}

// The integer a C caller stored in a.type, read as bytes: a C program may store any int there
// (e.g. 77), and loading such a value as a lantern_datatype is undefined behaviour in C++ (the
// enum has no fixed underlying type, so its valid values are only 0..7).
inline int datatype_value(const lantern_array &a) {
  std::underlying_type_t<lantern_datatype> raw{};
  static_assert(sizeof raw == sizeof a.type, "lantern_datatype is stored as its underlying type");
  std::memcpy(&raw, &a.type, sizeof raw);
  return static_cast<int>(raw);
}

// Unknown datatype values pass through unchanged, so validation can name them: DataType has a
// fixed underlying type (int), so every int is a valid DataType value and this cast is defined.
// ParticleArrays::validate() rejects values other than those of lantern_datatype.
inline BorrowedArray from_c(const lantern_array &a) {
  return {a.data, static_cast<DataType>(datatype_value(a)), a.stride_bytes};
}
inline lantern_array to_c(const BorrowedArray &a) {
  return {a.data, static_cast<lantern_datatype>(a.type), a.stride_bytes};
}

// Every field of a particle description, each array through `convert`: one list of the fields
// for both directions.
template <typename To, typename From, typename Convert>
To translate_particles(const From &in, Convert convert) {
  To out{};
  out.count = in.count;
  out.position = convert(in.position);
  out.position_x = convert(in.position_x);
  out.position_y = convert(in.position_y);
  out.position_z = convert(in.position_z);
  out.radius = convert(in.radius);
  out.scalar = convert(in.scalar);
  out.type = convert(in.type);
  out.id = convert(in.id);
  out.mask = convert(in.mask);
  out.mask_bits = in.mask_bits;
  return out;
}

inline ParticleDescription from_c(const lantern_particles &p) {
  return translate_particles<ParticleDescription>(p,
                                                  [](const lantern_array &a) { return from_c(a); });
}

inline lantern_particles to_c(const ParticleDescription &d) {
  return translate_particles<lantern_particles>(d, [](const BorrowedArray &a) { return to_c(a); });
}

static_assert(int(BondListing::kListedOnce) == LANTERN_BONDS_LISTED_ONCE &&
                  int(BondListing::kListedByBoth) == LANTERN_BONDS_LISTED_BY_BOTH,
              "BondListing and lantern_bond_listing must keep the same values");

// The bonds' listing as the int the C caller stored (as datatype_value, and for the same
// reason): BondListing has a fixed underlying type, so any int converts, and validation names
// values that are not a lantern_bond_listing.
inline BondListing listing_value(const lantern_bonds &b) {
  std::underlying_type_t<lantern_bond_listing> raw{};
  static_assert(sizeof raw == sizeof b.listing, "lantern_bond_listing is stored as its type");
  std::memcpy(&raw, &b.listing, sizeof raw);
  return static_cast<BondListing>(static_cast<int>(raw));
}

inline BondDescription from_c(const lantern_bonds &b) {
  BondDescription d;
  d.count = b.count;
  d.first = from_c(b.first);
  d.second = from_c(b.second);
  d.type = from_c(b.type);
  d.ghost_count = b.ghost_count;
  d.listing = listing_value(b);
  return d;
}

}  // namespace lantern
