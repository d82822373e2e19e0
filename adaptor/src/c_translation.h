// The C API's types <-> core's: field by field, pointers and strides only (never the particle
// data itself). Core has its own vocabulary (core/common/status.h,
// core/particles/particle_description.h) so that it never includes the public header; this file
// is where the two meet. The enums share numeric values, checked at compile time below.
#pragma once

#include "core/common/status.h"
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

// Unknown datatype values pass through unchanged, so validation can name them.
inline BorrowedArray from_c(const lantern_array &a) {
  return {a.data, static_cast<DataType>(a.type), a.stride_bytes};
}
inline lantern_array to_c(const BorrowedArray &a) {
  return {a.data, static_cast<lantern_datatype>(a.type), a.stride_bytes};
}

inline ParticleDescription from_c(const lantern_particles &p) {
  ParticleDescription d;
  d.count = p.count;
  d.position = from_c(p.position);
  d.position_x = from_c(p.position_x);
  d.position_y = from_c(p.position_y);
  d.position_z = from_c(p.position_z);
  d.radius = from_c(p.radius);
  d.scalar = from_c(p.scalar);
  d.type = from_c(p.type);
  d.id = from_c(p.id);
  return d;
}

inline lantern_particles to_c(const ParticleDescription &d) {
  lantern_particles p{};
  p.count = d.count;
  p.position = to_c(d.position);
  p.position_x = to_c(d.position_x);
  p.position_y = to_c(d.position_y);
  p.position_z = to_c(d.position_z);
  p.radius = to_c(d.radius);
  p.scalar = to_c(d.scalar);
  p.type = to_c(d.type);
  p.id = to_c(d.id);
  return p;
}

}  // namespace lantern
