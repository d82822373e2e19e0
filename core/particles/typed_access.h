// Tight, typed readers of the borrowed particle arrays for the per-particle passes (keys, bounds,
// culling). ParticleArrays::position(i) switches on the datatype for every element; these readers
// resolve the layout once per pass (float/double, interleaved/separate, radius array or constant)
// and hand the pass a reader whose get() compiles to plain loads.
//
// Ownership: readers borrow the simulation's arrays (no copies). Thread-safety: read-only, so any
// number of threads may read concurrently. Units: the simulation's.
#pragma once

#include <cstdint>
#include <cstring>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "core/particles/particle_arrays.h"

namespace lantern {

// memcpy: the simulation's arrays may be unaligned (byte strides, packed structs).
template <typename T>
inline T load_unaligned(const unsigned char *p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

// Interleaved xyz of type T with a byte stride.
template <typename T>
struct InterleavedPositions {
  const unsigned char *base;
  int64_t stride;
  glm::dvec3 get(int64_t i) const {
    const unsigned char *p = base + i * stride;
    return {double(load_unaligned<T>(p)), double(load_unaligned<T>(p + sizeof(T))),
            double(load_unaligned<T>(p + 2 * sizeof(T)))};
  }
  // Asks for particle i's position ahead of get(i): a brick's particles lie scattered in a
  // published order that is not spatial (a gas), one cache and TLB miss each otherwise.
  void prefetch(int64_t i) const { __builtin_prefetch(base + i * stride, 0, 3); }
};

// Three separate strided arrays of type T.
template <typename T>
struct SeparatePositions {
  const unsigned char *base[3];
  int64_t stride[3];
  glm::dvec3 get(int64_t i) const {
    return {double(load_unaligned<T>(base[0] + i * stride[0])),
            double(load_unaligned<T>(base[1] + i * stride[1])),
            double(load_unaligned<T>(base[2] + i * stride[2]))};
  }
  void prefetch(int64_t i) const {
    for (int a = 0; a < 3; ++a) __builtin_prefetch(base[a] + i * stride[a], 0, 3);
  }
};

// Separate arrays of different types (legal, rare): falls back to the converting accessor.
struct MixedPositions {
  const ParticleArrays *p;
  glm::dvec3 get(int64_t i) const { return p->position(i); }
  void prefetch(int64_t) const {}  // rare layout: not worth resolving the arrays
};

// Calls f(reader) with the reader that matches the particles' position layout. Positions are
// validated to be float32 or float64 (particle_arrays.cpp), so these four cover every case.
template <typename F>
decltype(auto) visit_positions(const ParticleArrays &p, F &&f) {
  const auto bytes = [](const StridedArray &a) {
    return static_cast<const unsigned char *>(a.data());
  };
  if (p.interleaved()) {
    const StridedArray &a = p.position_array(0);
    if (a.type() == DataType::kFloat32)
      return f(InterleavedPositions<float>{bytes(a), a.stride_bytes()});
    return f(InterleavedPositions<double>{bytes(a), a.stride_bytes()});
  }
  const StridedArray &x = p.position_array(0), &y = p.position_array(1), &z = p.position_array(2);
  if (x.type() == DataType::kFloat32 && y.type() == DataType::kFloat32 &&
      z.type() == DataType::kFloat32)
    return f(SeparatePositions<float>{{bytes(x), bytes(y), bytes(z)},
                                      {x.stride_bytes(), y.stride_bytes(), z.stride_bytes()}});
  if (x.type() == DataType::kFloat64 && y.type() == DataType::kFloat64 &&
      z.type() == DataType::kFloat64)
    return f(SeparatePositions<double>{{bytes(x), bytes(y), bytes(z)},
                                       {x.stride_bytes(), y.stride_bytes(), z.stride_bytes()}});
  return f(MixedPositions{&p});
}

// A strided real array of type T (radius).
template <typename T>
struct StridedReals {
  const unsigned char *base;
  int64_t stride;
  double get(int64_t i) const { return double(load_unaligned<T>(base + i * stride)); }
};

// One value for every particle (the scene's radius).
struct ConstantReal {
  double value;
  double get(int64_t) const { return value; }
};

// Calls f(reader) with the radius reader: the published array when `per_particle` and present,
// else the constant `radius`.
template <typename F>
decltype(auto) visit_radii(const ParticleArrays &p, bool per_particle, double radius, F &&f) {
  if (!per_particle || !p.has_radius()) return f(ConstantReal{radius});
  const StridedArray &a = p.radius_array();
  const auto *b = static_cast<const unsigned char *>(a.data());
  if (a.type() == DataType::kFloat32) return f(StridedReals<float>{b, a.stride_bytes()});
  return f(StridedReals<double>{b, a.stride_bytes()});
}

// Every particle kept (no mask published): get() is a constant the compiler folds away, so the
// passes cost nothing extra without a group.
struct KeepAll {
  bool get(int64_t) const { return true; }
};

// The group of ParticleDescription::mask: particle i is kept when (mask[i] & bits) != 0.
template <typename T>
struct KeepMasked {
  const unsigned char *base;
  int64_t stride;
  int64_t bits;
  bool get(int64_t i) const { return (int64_t(load_unaligned<T>(base + i * stride)) & bits) != 0; }
};

// Calls f(reader) with the reader of which particles are kept: KeepAll without a mask.
template <typename F>
decltype(auto) visit_kept(const ParticleArrays &p, F &&f) {
  if (!p.has_mask()) return f(KeepAll{});
  const StridedArray &a = p.mask_array();
  const auto *b = static_cast<const unsigned char *>(a.data());
  if (a.type() == DataType::kInt32)
    return f(KeepMasked<int32_t>{b, a.stride_bytes(), p.mask_bits()});
  return f(KeepMasked<int64_t>{b, a.stride_bytes(), p.mask_bits()});
}

}  // namespace lantern
