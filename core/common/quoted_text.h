// Text from files and from the user (configuration values, dump lines) made safe to print in an
// error message: unprintable bytes escaped and long text cut short, so that a message about a
// binary file never sends raw bytes to a terminal. The one place every message that quotes
// file content goes through (configuration, LAMMPS and H5MD readers, lantern-render).
//
// Pure functions, thread-safe.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace lantern {

// Longest excerpt, in bytes of the original text, that quoted_text() keeps by default.
constexpr size_t kQuotedTextLimit = 60;

// `text` between single quotes, with \n, \r, \t, \\, \' and \0 escaped, every other byte
// outside printable ASCII (0x20..0x7e) written as \xNN, and, when `text` is longer than `limit`
// bytes, only its first `limit` bytes followed by "..." after the closing quote. E.g.
// quoted_text("a\x8f") == "'a\\x8f'".
std::string quoted_text(std::string_view text, size_t limit = kQuotedTextLimit);

// The same escaping without quotes or cutting, for a whole message that may hold such bytes.
std::string escaped_text(std::string_view text);

// A name read from a file (a YAML key, a dump's column name) as written when it is printable and
// at most kQuotedTextLimit bytes, else quoted_text(name).
std::string name_text(std::string_view name);

}  // namespace lantern
