#include "core/color/colormap_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "core/config/config_file.h"

namespace lantern {
namespace {

// The numbers of one line (separators: blanks and commas); false on a word that is no number.
bool numbers_of(const std::string &line, std::vector<double> *out, std::string *bad) {
  out->clear();
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (std::isspace(static_cast<unsigned char>(line[i])) || line[i] == ','))
      ++i;
    if (i >= line.size()) break;
    size_t end = i;
    while (end < line.size() && !std::isspace(static_cast<unsigned char>(line[end])) &&
           line[end] != ',')
      ++end;
    const std::string word = line.substr(i, end - i);
    char *stop = nullptr;
    const double v = std::strtod(word.c_str(), &stop);
    if (stop != word.c_str() + word.size() || !std::isfinite(v)) {
      *bad = word;
      return false;
    }
    out->push_back(v);
    i = end;
  }
  return true;
}

}  // namespace

Status parse_colormap_text(const std::string &text, const std::string &source,
                           std::vector<std::array<double, 3>> *colors) {
  colors->clear();
  std::istringstream in(text);
  std::string line, bad;
  std::vector<double> values;
  double largest = 0.0;
  const auto fail = [&](int number, const std::string &what) {
    return Status(StatusCode::kConfig,
                  "colormap file '" + source + "' line " + std::to_string(number) + ": " + what);
  };
  for (int number = 1; std::getline(in, line); ++number) {
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    if (!numbers_of(line, &values, &bad))
      return fail(number, "'" + bad.substr(0, 40) + "' is not a finite number");
    if (values.empty()) continue;
    if (values.size() != 3)
      return fail(number, "expected 3 numbers (r g b), got " + std::to_string(values.size()));
    for (const double v : values) {
      if (v < 0.0) return fail(number, "a colour component is negative");
      if (v > 255.0) return fail(number, "a colour component exceeds 255");
      largest = std::max(largest, v);
    }
    if (colors->size() == kMaxColormapColors)
      return fail(number, "more than " + std::to_string(kMaxColormapColors) + " colours");
    colors->push_back({values[0], values[1], values[2]});
  }
  if (colors->size() < 2)
    return {StatusCode::kConfig, "colormap file '" + source + "': needs at least 2 colours, has " +
                                     std::to_string(colors->size())};
  if (largest > 1.0)
    for (auto &c : *colors)
      for (double &v : c) v /= 255.0;
  return {};
}

Status read_colormap_file(const std::string &path, std::vector<std::array<double, 3>> *colors) {
  // As a configuration file is read: only a regular file, at most kMaxConfigBytes. A FIFO nobody
  // wrote to blocked lantern_open in open() for ever, /dev/zero grew the text until memory ran
  // out, and a multi-gigabyte file was read whole before its first line was parsed.
  std::string text;
  if (const std::string why = read_config_file(path, &text, "a colormap is a text file of colours");
      !why.empty())
    return {StatusCode::kConfig, "cannot read colormap file '" + path + "': " + why};
  return parse_colormap_text(text, path, colors);
}

}  // namespace lantern
