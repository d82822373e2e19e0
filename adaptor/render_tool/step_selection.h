// The --steps option of lantern-render: "a,b,c" (exactly these steps) or "a:b" (every frame with
// a <= step <= b). Turns the option into the indices of the frames to render.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/dump/particle_frame.h"

namespace lantern {

// Empty option: every frame. Returns "" and the frame indices in file order, or an error
// ("--steps: 'x' is not an integer", "--steps: step 7 is not in the input (steps 0..100)").
std::string select_frames(const std::string &option, const std::vector<FrameInfo> &frames,
                          std::vector<size_t> *out);

}  // namespace lantern
