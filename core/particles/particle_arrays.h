// Typed, validated access to the particle arrays a simulation lends Lantern.
//
// Ownership: ParticleArrays never owns or copies the data; it stores the pointers and strides of
// ParticleDescription. The caller keeps the arrays alive (lantern_publish in the C API).
// Thread-safety: read-only after construction, so concurrent readers are fine. Units: those of the
// simulation.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

#include <glm/vec3.hpp>

#include "core/common/status.h"
#include "core/particles/particle_description.h"

namespace lantern {

// One borrowed strided array, read element by element with conversion to the wanted type.
class StridedArray {
 public:
  StridedArray() = default;
  StridedArray(const void *data, DataType type, int64_t stride_bytes)
      : base_(static_cast<const unsigned char *>(data)), type_(type), stride_(stride_bytes) {}

  bool present() const { return base_ != nullptr && type_ != DataType::kNone; }
  DataType type() const { return type_; }
  int64_t stride_bytes() const { return stride_; }
  const void *data() const { return base_; }

  // Element i, component c (for interleaved vectors), converted to double.
  double real(int64_t i, int c = 0) const {
    const unsigned char *p = base_ + i * stride_;
    switch (type_) {
      case DataType::kFloat32:
        return load<float>(p, c);
      case DataType::kFloat64:
        return load<double>(p, c);
      case DataType::kInt32:
        return load<int32_t>(p, c);
      case DataType::kInt64:
        return static_cast<double>(load<int64_t>(p, c));
      default:
        return 0.0;
    }
  }
  int64_t integer(int64_t i) const {
    const unsigned char *p = base_ + i * stride_;
    switch (type_) {
      case DataType::kInt32:
        return load<int32_t>(p, 0);
      case DataType::kInt64:
        return load<int64_t>(p, 0);
      case DataType::kFloat32:
        return static_cast<int64_t>(load<float>(p, 0));
      case DataType::kFloat64:
        return static_cast<int64_t>(load<double>(p, 0));
      default:
        return 0;
    }
  }

 private:
  // memcpy: the caller's array may be unaligned (padded structs, byte strides).
  template <typename T>
  static T load(const unsigned char *p, int c) {
    T v;
    std::memcpy(&v, p + c * sizeof(T), sizeof(T));
    return v;
  }

  const unsigned char *base_ = nullptr;
  DataType type_ = DataType::kNone;
  int64_t stride_ = 0;
};

// Validates one borrowed array of `count` entries of `components` elements each, real (float32 or
// float64) when `want_real`, else integer (int32 or int64); an absent array (no data, no type) is
// fine and leaves *out absent. OK with *out set, or kInvalidArgument naming `field` (the whole
// name, e.g. "particles.position" or "bonds.first").
Status check_borrowed_array(const BorrowedArray &a, const std::string &field, int components,
                            bool want_real, int64_t count, StridedArray *out);

// The validated particle set of one rank. Build it with ParticleArrays::validate().
class ParticleArrays {
 public:
  ParticleArrays() = default;

  // Checks a description (types, strides, NULL pointers, negative count) and, on success, fills
  // *out and returns OK. On failure returns kInvalidArgument with a message naming the offending
  // field (e.g. "particles.position.stride_bytes: 8 is shorter than 3 float64 (24)").
  // It reads no element: NaN positions are found later, per frame.
  static Status validate(const ParticleDescription &p, ParticleArrays *out);

  int64_t count() const { return count_; }
  glm::dvec3 position(int64_t i) const {
    if (interleaved_) return {pos_[0].real(i, 0), pos_[0].real(i, 1), pos_[0].real(i, 2)};
    return {pos_[0].real(i), pos_[1].real(i), pos_[2].real(i)};
  }
  bool has_radius() const { return radius_.present(); }
  double radius(int64_t i) const { return radius_.real(i); }
  bool has_scalar() const { return scalar_.present(); }
  double scalar(int64_t i) const { return scalar_.real(i); }
  bool has_type() const { return type_.present(); }
  int64_t type(int64_t i) const { return type_.integer(i); }
  bool has_id() const { return id_.present(); }
  int64_t id(int64_t i) const { return id_.integer(i); }
  // The group (ParticleDescription::mask): without a mask every particle is kept.
  bool has_mask() const { return mask_.present(); }
  int64_t mask_bits() const { return mask_bits_; }
  bool kept(int64_t i) const { return !mask_.present() || (mask_.integer(i) & mask_bits_) != 0; }
  // Particles in the group (count() without a mask): one pass over the mask.
  int64_t kept_count() const;

  bool interleaved() const { return interleaved_; }
  // Component arrays: [0] is the interleaved array when interleaved(), else x, y, z.
  const StridedArray &position_array(int c) const { return pos_[c]; }
  const StridedArray &radius_array() const { return radius_; }
  const StridedArray &scalar_array() const { return scalar_; }
  const StridedArray &type_array() const { return type_; }
  const StridedArray &id_array() const { return id_; }
  const StridedArray &mask_array() const { return mask_; }

 private:
  int64_t count_ = 0;
  bool interleaved_ = true;
  StridedArray pos_[3];
  StridedArray radius_, scalar_, type_, id_, mask_;
  int64_t mask_bits_ = 0;
};

}  // namespace lantern
