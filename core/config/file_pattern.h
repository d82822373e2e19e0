// Output file-name patterns: "out/{scene}/frame_{step:06d}.png".
//
// Placeholders: {step} (decimal), {step:0Nd} (zero-padded to N digits, N = 1..20), {scene}
// (the scene name). "{{" and "}}" stand for literal braces. Anything else in braces is an error,
// reported by validate_pattern() when the configuration loads. Pure functions, thread-safe.
#pragma once

#include <cstdint>
#include <string>

#include "core/common/status.h"

namespace lantern {

// OK if `pattern` is well formed, else kConfig with a message naming the offending placeholder.
Status validate_pattern(const std::string &pattern);

// The file name for `step` of `scene`. Precondition: validate_pattern(pattern).ok(); on a
// malformed pattern, unknown placeholders are copied through verbatim (never throws).
std::string expand_pattern(const std::string &pattern, int64_t step, const std::string &scene);

// True if the pattern uses {scene} (so several scenes sharing it write different files).
bool pattern_uses_scene(const std::string &pattern);

}  // namespace lantern
