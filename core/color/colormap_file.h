// A custom colormap from a text file (`colormap: {file: PATH}`): one colour per line, three
// numbers separated by spaces, tabs or commas ("0.1 0.2 0.3", "26,51,77"); empty lines and text
// after '#' are ignored. Components are in [0, 1], or all in [0, 255] when any exceeds 1 (as
// byte-valued tables are written). At least 2 and at most 4096 colours, evenly spaced over the
// map like a `colormap: [[r,g,b], ...]` list. Pure functions, thread-safe.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/common/status.h"

namespace lantern {

inline constexpr size_t kMaxColormapColors = 4096;

// Parses `text`; on error kConfig naming `source` and the line.
Status parse_colormap_text(const std::string &text, const std::string &source,
                           std::vector<std::array<double, 3>> *colors);

// Reads and parses the file at `path`; kConfig naming the file when it cannot be read.
Status read_colormap_file(const std::string &path, std::vector<std::array<double, 3>> *colors);

}  // namespace lantern
