// The global simulation box: an axis-aligned block, each axis periodic or closed by reflecting
// walls.
#pragma once

#include <array>

#include "vec3.h"

namespace mini_md {

struct Box {
  Vec3 lo{0, 0, 0};
  Vec3 hi{0, 0, 0};
  std::array<bool, 3> periodic{true, true, true};

  double length(int d) const { return hi[d] - lo[d]; }
  double volume() const { return length(0) * length(1) * length(2); }
};

}  // namespace mini_md
