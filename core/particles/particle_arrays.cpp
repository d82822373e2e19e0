#include "core/particles/particle_arrays.h"

#include <cstdint>
#include <limits>
#include <string>

namespace lantern {
namespace {

int64_t element_size(DataType t) {
  switch (t) {
    case DataType::kFloat32:
    case DataType::kInt32:
      return 4;
    case DataType::kFloat64:
    case DataType::kInt64:
      return 8;
    default:
      return 0;
  }
}

const char *type_name(DataType t) {
  switch (t) {
    case DataType::kFloat32:
      return "float32";
    case DataType::kFloat64:
      return "float64";
    case DataType::kInt32:
      return "int32";
    case DataType::kInt64:
      return "int64";
    default:
      return "none";
  }
}

bool is_real(DataType t) {
  return t == DataType::kFloat32 || t == DataType::kFloat64;
}
bool is_integer(DataType t) {
  return t == DataType::kInt32 || t == DataType::kInt64;
}

bool given(const BorrowedArray &a) {
  return a.data != nullptr || a.type != DataType::kNone;
}

Status check_array(const BorrowedArray &a, const char *name, int components, bool want_real,
                   int64_t count, StridedArray *out) {
  return check_borrowed_array(a, std::string("particles.") + name, components, want_real, count,
                              out);
}

}  // namespace

Status check_borrowed_array(const BorrowedArray &a, const std::string &field, int components,
                            bool want_real, int64_t count, StridedArray *out) {
  const auto invalid = [&field](const std::string &what) {
    return Status(StatusCode::kInvalidArgument, field + what);
  };
  if (a.type == DataType::kNone && a.data == nullptr) return {};  // absent
  const int64_t esize = element_size(a.type);
  if (esize == 0)
    return invalid(".type: unknown datatype " + std::to_string(static_cast<int>(a.type)));
  if (want_real && !is_real(a.type))
    return invalid(".type: must be DataType::kFloat32 or DataType::kFloat64, got " +
                   std::string(type_name(a.type)));
  if (!want_real && !is_integer(a.type))
    return invalid(".type: must be DataType::kInt32 or DataType::kInt64, got " +
                   std::string(type_name(a.type)));
  if (a.data == nullptr && count > 0) return invalid(".data: NULL with count > 0");
  const int64_t natural = esize * components;
  const int64_t stride = a.stride_bytes == 0 ? natural : a.stride_bytes;
  if (stride < natural)
    return invalid(".stride_bytes: " + std::to_string(a.stride_bytes) + " is shorter than " +
                   std::to_string(components) + " " + type_name(a.type) + " (" +
                   std::to_string(natural) + " bytes)");
  *out = StridedArray(a.data, a.type, stride);
  return {};
}

Status ParticleArrays::validate(const ParticleDescription &p, ParticleArrays *out) {
  const auto invalid = [](std::string message) {
    return Status(StatusCode::kInvalidArgument, std::move(message));
  };
  if (p.count < 0) return invalid("particles.count: negative (" + std::to_string(p.count) + ")");
  // The bricks index a rank's particles in 32 bits (brick_set.h); more overflowed their counts
  // and wrote past the index arrays.
  if (p.count > std::numeric_limits<uint32_t>::max())
    return invalid("particles.count: " + std::to_string(p.count) +
                   " on one rank; Lantern indexes a rank's particles in 32 bits (below 2^32): "
                   "spread them over more ranks");
  ParticleArrays r;
  r.count_ = p.count;
  const bool inter = given(p.position);
  const bool separate = given(p.position_x) || given(p.position_y) || given(p.position_z);
  if (inter && separate)
    return invalid(
        "particles.position: give either the interleaved array or position_x/y/z, not both");
  if (!inter && !separate) {
    if (p.count > 0) return invalid("particles.position: NULL positions with count > 0");
  } else if (inter) {
    r.interleaved_ = true;
    if (Status s = check_array(p.position, "position", 3, true, p.count, &r.pos_[0]); !s.ok())
      return s;
  } else {
    r.interleaved_ = false;
    const BorrowedArray *c[3] = {&p.position_x, &p.position_y, &p.position_z};
    const char *names[3] = {"position_x", "position_y", "position_z"};
    for (int k = 0; k < 3; ++k) {
      if (!given(*c[k]) && p.count > 0)
        return invalid(std::string("particles.") + names[k] + ": NULL positions with count > 0");
      if (Status s = check_array(*c[k], names[k], 1, true, p.count, &r.pos_[k]); !s.ok()) return s;
    }
  }
  if (Status s = check_array(p.radius, "radius", 1, true, p.count, &r.radius_); !s.ok()) return s;
  if (Status s = check_array(p.scalar, "scalar", 1, true, p.count, &r.scalar_); !s.ok()) return s;
  if (Status s = check_array(p.type, "type", 1, false, p.count, &r.type_); !s.ok()) return s;
  if (Status s = check_array(p.id, "id", 1, false, p.count, &r.id_); !s.ok()) return s;
  if (Status s = check_array(p.mask, "mask", 1, false, p.count, &r.mask_); !s.ok()) return s;
  if (given(p.mask) && p.mask_bits == 0)
    return invalid(
        "particles.mask_bits: 0 with a mask given would keep no particle (give the group's bits, "
        "or no mask to keep every particle)");
  r.mask_bits_ = p.mask_bits;
  *out = r;
  return {};
}

int64_t ParticleArrays::kept_count() const {
  if (!has_mask()) return count_;
  int64_t kept_particles = 0;
  for (int64_t i = 0; i < count_; ++i) kept_particles += kept(i) ? 1 : 0;
  return kept_particles;
}

}  // namespace lantern
