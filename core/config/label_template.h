// Overlay label templates: "step {step:06d}  t = {time:.2f} ps  ({scene})".
//
// Fields: {step} (decimal; {step:06d} zero-padded, {step:8d} space-padded), {time} (shortest
// form, as %g; {time:.2f}, {time:.3e}, {time:.4g} and a width, e.g. {time:8.2f}), {scene} (the
// scene's name). "{{" and "}}" are literal braces; anything else in braces is an error that
// validate_label_template() names when the configuration loads. Pure functions, thread-safe.
#pragma once

#include <cstdint>
#include <string>

#include "core/common/status.h"

namespace lantern {

// OK if `text` is a well-formed template, else kConfig naming the offending field.
Status validate_label_template(const std::string &text);

// The label's text for one frame. Precondition: validate_label_template(text).ok(); malformed
// fields are copied through verbatim (never throws).
std::string expand_label(const std::string &text, int64_t step, double time,
                         const std::string &scene);

}  // namespace lantern
