#include "core/dump/box.h"

#include <cmath>

namespace lantern {

Status validate_box(const Box &box) {
  const auto invalid = [](std::string message) {
    return Status(StatusCode::kInvalidArgument, std::move(message));
  };
  for (int a = 0; a < 3; ++a) {
    const std::string axis = "[" + std::to_string(a) + "]";
    if (!std::isfinite(box.low[a])) return invalid("low" + axis + " is not finite");
    if (!std::isfinite(box.high[a])) return invalid("high" + axis + " is not finite");
    if (box.low[a] > box.high[a])
      return invalid("low" + axis + " = " + std::to_string(box.low[a]) + " is above high" + axis +
                     " = " + std::to_string(box.high[a]));
    // An edge whose length overflows (low -1e308, high 1e308) made every periodic bond's end NaN:
    // the bonds were silently not drawn.
    if (!std::isfinite(box.high[a] - box.low[a]))
      return invalid("high" + axis + " - low" + axis + " overflows (" + std::to_string(box.low[a]) +
                     " to " + std::to_string(box.high[a]) + ")");
  }
  static const char *const kTilt[3] = {"xy", "xz", "yz"};
  for (int t = 0; t < 3; ++t)
    if (!std::isfinite(box.tilt[t]))
      return invalid(std::string("tilt[") + std::to_string(t) + "] (" + kTilt[t] +
                     ") is not finite");
  return {};
}

}  // namespace lantern
