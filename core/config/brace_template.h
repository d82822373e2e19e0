// The brace syntax shared by output file-name patterns (file_pattern.h) and overlay label
// templates (label_template.h): literal text, "{{" and "}}" for braces, and fields "{body}" whose
// meaning the caller gives. Pure functions, thread-safe.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "core/common/status.h"

namespace lantern {

// Expands one field's body (the text between the braces). Returns its text, or nullopt with
// *why saying what is wrong with it.
using BraceField =
    std::function<std::optional<std::string>(const std::string &body, std::string *why)>;

// Walks `text` once. With `error` set, stops at the first problem (an unmatched brace or a field
// `field` rejects) and describes it there as kConfig, returning ""; with `error` null, expands,
// copying malformed parts through verbatim (never throws).
std::string expand_braces(const std::string &text, const BraceField &field, Status *error);

}  // namespace lantern
