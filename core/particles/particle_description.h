// How a simulation describes the particle arrays it lends Lantern: pointers, element types and
// byte strides, nothing copied. This is core's own vocabulary for what the C API calls
// lantern_array / ParticleDescription (adaptor/ translates one to the other field by field; the
// numeric values of DataType are those of DataType).
//
// Ownership: a description borrows; whoever fills it keeps the arrays alive (see ParticleArrays).
// Units: the simulation's.
#pragma once

#include <cstdint>

namespace lantern {

// Element type of a borrowed array. kNone marks an absent (optional) array.
enum class DataType { kNone = 0, kFloat32 = 1, kFloat64 = 2, kInt32 = 3, kInt64 = 4 };

// One borrowed, strided array: element i is at (const char *)data + i * stride_bytes.
// stride_bytes == 0 means tightly packed; a default-constructed array means "absent".
struct BorrowedArray {
  const void *data = nullptr;
  DataType type = DataType::kNone;
  int64_t stride_bytes = 0;
};

// The particles one rank owns: positions interleaved (`position`) or as three arrays
// (`position_x/y/z`), and the optional per-particle arrays.
struct ParticleDescription {
  int64_t count = 0;
  BorrowedArray position;
  BorrowedArray position_x, position_y, position_z;
  BorrowedArray radius, scalar, type, id;
  // A group: with `mask` present, particle i counts only if (mask[i] & mask_bits) != 0; the others
  // are skipped by every stage (bounds, bricks, drawing, dumps). mask_bits is read only with a
  // mask.
  BorrowedArray mask;
  int64_t mask_bits = 0;
};

}  // namespace lantern
