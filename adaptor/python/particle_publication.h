// The keyword arguments of Context.publish() turned into one lantern_particles, borrowing every
// array in place: shapes and lengths are checked here, element types and byte order by
// BorrowedBuffer, and (n, 3) positions whose x, y, z are not adjacent become three component
// views. Nothing is copied.
//
// Ownership: a ParticlePublication holds every array it describes (see BorrowedBuffer) for as
// long as it lives; lantern_publish() borrows the pointers, so keep the publication until the
// next publish or close. Thread-safety: build and destroy it with the GIL held.
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "borrowed_buffer.h"
#include "lantern/lantern.h"

namespace lantern_python {

// The arrays given to Context.publish(); None (absent) for those not given.
struct PublishArguments {
  pybind11::object position, position_x, position_y, position_z;
  pybind11::object radius, scalar, type, id, mask;
  int64_t mask_bits = 0;
};

class ParticlePublication {
 public:
  // Throws pybind11::value_error naming the array that cannot be borrowed as it is.
  static ParticlePublication describe(const PublishArguments &args);

  const lantern_particles &particles() const { return particles_; }
  // The data pointer handed to Lantern for each field given, in field order.
  const std::vector<std::pair<std::string, uintptr_t>> &pointers() const { return pointers_; }

 private:
  lantern_array one_dimensional(const pybind11::object &object, const char *name, ElementKind kind);
  void positions(const pybind11::object &object);
  void record(const char *name, const lantern_array &a);

  lantern_particles particles_{};
  bool counted_ = false;  // particles_.count is known (from the positions)
  std::vector<BorrowedBuffer> held_;
  std::vector<std::pair<std::string, uintptr_t>> pointers_;
};

}  // namespace lantern_python
