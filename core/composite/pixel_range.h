// A run of pixels of a frame in row-major order: what compositing hands from rank to rank.
#pragma once

#include <cstddef>

namespace lantern {

// Pixels [lo, hi) of a frame in row-major order.
struct PixelRange {
  size_t lo = 0;
  size_t hi = 0;
  size_t size() const { return hi - lo; }
};

}  // namespace lantern
