// What CompositeMethod::kAuto runs: the method measured fastest on this machine class for a
// (rank count, pixel count) case, from tests/bench/composite.sh (table in method_table.cpp).
//
// Why a fixed table and not an in-process calibration: the choice must be identical on every
// rank without extra communication, and a pure function of (ranks, pixels) guarantees that.
#pragma once

#include <cstddef>

#include "core/composite/depth_compositor.h"

namespace lantern {

// Never returns kAuto. ranks >= 2.
CompositeMethod auto_composite_method(int ranks, size_t pixels);

}  // namespace lantern
