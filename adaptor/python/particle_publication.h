// The keyword arguments of Context.publish() turned into one lantern_particles (and, with bonds
// or ghosts, one lantern_bonds), borrowing every array in place: shapes and lengths are checked
// here, element types and byte order by BorrowedBuffer, (n, 3) positions whose x, y, z are not
// adjacent become three component views, and the two columns of an (m, 2) bond array become the
// bonds' `first` and `second` views. Nothing is copied.
//
// Ghosts: with ghost_count = g, the last g rows of every particle array are ghosts (bond ends
// owned by another rank): the particle count handed to lantern_publish() is n - g.
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
  pybind11::object bonds, bond_type;  // (m, 2) and (m,) int32/int64, or None
  int64_t ghost_count = 0;
  std::string bonds_listed = "once";  // "once" or "by_both" (lantern_bond_listing)
};

class ParticlePublication {
 public:
  // Throws pybind11::value_error naming the array that cannot be borrowed as it is.
  static ParticlePublication describe(const PublishArguments &args);

  const lantern_particles &particles() const { return particles_; }
  // Whether lantern_publish_bonds() must follow lantern_publish() (bonds or ghosts were given).
  bool has_bonds() const { return has_bonds_; }
  const lantern_bonds &bonds() const { return bonds_; }
  // The data pointer handed to Lantern for each field given, in field order.
  const std::vector<std::pair<std::string, uintptr_t>> &pointers() const { return pointers_; }

 private:
  lantern_array one_dimensional(const pybind11::object &object, const char *name, ElementKind kind);
  void positions(const pybind11::object &object);
  void describe_bonds(const PublishArguments &args);
  void record(const char *name, const lantern_array &a);

  lantern_particles particles_{};
  lantern_bonds bonds_{};
  bool has_bonds_ = false;
  bool counted_ = false;  // particles_.count is known (from the positions)
  std::vector<BorrowedBuffer> held_;
  std::vector<std::pair<std::string, uintptr_t>> pointers_;
};

}  // namespace lantern_python
