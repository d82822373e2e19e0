// The simulation box that particle dumps record (H5MD `box`): an axis-aligned box and which of
// its axes are periodic. Set by the simulation with lantern_set_box(); when it is not set, dumps
// use the global bounds of the particles and non-periodic boundaries.
#pragma once

#include <array>
#include <string>

#include "core/common/status.h"

namespace lantern {

struct Box {
  std::array<double, 3> low{0, 0, 0};
  std::array<double, 3> high{0, 0, 0};
  std::array<bool, 3> periodic{false, false, false};

  std::array<double, 3> edges() const {
    return {high[0] - low[0], high[1] - low[1], high[2] - low[2]};
  }
};

// OK when the box is usable (finite corners, low <= high on every axis), else kInvalidArgument
// with a message naming the axis, e.g. "low[1] = 5 is above high[1] = 2".
Status validate_box(const Box &box);

}  // namespace lantern
