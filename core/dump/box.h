// The simulation box that particle dumps record (H5MD `box`), the box overlay draws and bonds take
// their minimum image in: an axis-aligned or a triclinic box and which of its axes are periodic.
// Set by the simulation with lantern_set_box() or lantern_set_triclinic_box(); when it is not
// set, dumps use the global bounds of the particles and non-periodic boundaries.
#pragma once

#include <array>
#include <string>

#include "core/common/status.h"

namespace lantern {

struct Box {
  std::array<double, 3> low{0, 0, 0};
  std::array<double, 3> high{0, 0, 0};
  std::array<bool, 3> periodic{false, false, false};
  // Triclinic, in LAMMPS's restricted form: the edge vectors from `low` are a = (lx, 0, 0),
  // b = (xy, ly, 0) and c = (xz, yz, lz), where l = high - low and tilt = {xy, xz, yz}. Set by
  // lantern_set_triclinic_box, zero tilt included (a LAMMPS box that shears from zero tilt
  // stays triclinic: its dumps record the edges as a matrix from the first frame on).
  bool triclinic = false;
  std::array<double, 3> tilt{0, 0, 0};

  std::array<double, 3> edges() const {
    return {high[0] - low[0], high[1] - low[1], high[2] - low[2]};
  }
  // The edge vectors a, b, c as rows (H5MD's `edges` of a triclinic box).
  std::array<std::array<double, 3>, 3> edge_vectors() const {
    const auto l = edges();
    return {{{l[0], 0.0, 0.0}, {tilt[0], l[1], 0.0}, {tilt[1], tilt[2], l[2]}}};
  }
};

// OK when the box is usable (finite corners, low <= high on every axis, finite tilt), else
// kInvalidArgument with a message naming the axis, e.g. "low[1] = 5 is above high[1] = 2".
Status validate_box(const Box &box);

}  // namespace lantern
