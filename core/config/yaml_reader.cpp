#include "core/config/yaml_reader.h"

#include <cmath>
#include <map>
#include <sstream>

#include "core/common/quoted_text.h"
#include "core/config/key_suggestion.h"

namespace lantern {

namespace {

std::string join(const std::vector<std::string> &items, const char *separator) {
  std::string out;
  for (const std::string &item : items) out += (out.empty() ? "" : separator) + item;
  return out;
}

// The value as the user wrote it, for "got ..." in messages (escaped and cut short: a binary
// file read as YAML is one long scalar).
std::string shown(const YAML::Node &node) {
  if (node.IsScalar()) return quoted_text(node.Scalar());
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "nothing";
}

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

std::string child_path(const std::string &parent, const std::string &key) {
  return parent.empty() ? key : parent + "." + key;
}

std::string index_path(const std::string &parent, size_t index) {
  return parent + "[" + std::to_string(index) + "]";
}

void YamlReader::fail(const YAML::Node &where, const std::string &path,
                      const std::string &what) const {
  std::string message = source_;
  const YAML::Mark mark = where.IsDefined() ? where.Mark() : YAML::Mark::null_mark();
  if (!mark.is_null()) message += " line " + std::to_string(mark.line + 1);
  message += ": " + (path.empty() ? std::string("top level") : path) + ": " + what;
  // Values in `what` are quoted with quoted_text(); keys in `path` come from the document too.
  throw ConfigError(escaped_text(message));
}

void YamlReader::check_map(const YAML::Node &node, const std::string &path,
                           const std::vector<std::string> &allowed) const {
  if (node.IsNull()) return;
  if (!node.IsMap())
    fail(node, path,
         "expected a mapping with keys (" + join(allowed, ", ") + "), got " + shown(node));
  std::map<std::string, int> first_line;
  for (const auto &entry : node) {
    const YAML::Node &key_node = entry.first;
    if (!key_node.IsScalar()) fail(key_node, path, "keys must be plain names");
    const std::string key = key_node.Scalar();
    const std::string key_path = child_path(path, name_text(key));
    bool known = false;
    for (const std::string &candidate : allowed) known = known || candidate == key;
    if (!known) fail(key_node, key_path, unknown_key_text(key, allowed));
    const int line = key_node.Mark().line + 1;
    const auto [it, inserted] = first_line.emplace(key, line);
    if (!inserted)
      fail(key_node, key_path,
           "duplicate key " + quoted_text(key) + " (first given at line " +
               std::to_string(it->second) + ")");
  }
}

std::string YamlReader::unknown_key_text(const std::string &key,
                                         const std::vector<std::string> &allowed) const {
  std::string text = "unknown key " + quoted_text(key) + "; " + suggestion_text(key, allowed);
  const auto home = key_homes_.find(key);
  if (home != key_homes_.end()) text += "; '" + key + "' is a key of " + join(home->second, " / ");
  return text;
}

void YamlReader::check_sequence(const YAML::Node &node, const std::string &path) const {
  if (!node.IsSequence()) fail(node, path, "expected a list, got " + shown(node));
}

int64_t YamlReader::read_int(const YAML::Node &node, const std::string &path, int64_t lo,
                             int64_t hi) const {
  int64_t value = 0;
  const std::string allowed =
      "must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi);
  if (!node.IsScalar() || !YAML::convert<int64_t>::decode(node, value))
    fail(node, path, allowed + ", got " + shown(node));
  if (value < lo || value > hi) fail(node, path, allowed + ", got " + std::to_string(value));
  return value;
}

double YamlReader::read_finite(const YAML::Node &node, const std::string &path) const {
  double value = 0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value))
    fail(node, path, "must be a finite number, got " + shown(node));
  return value;
}

double YamlReader::read_in_range(const YAML::Node &node, const std::string &path, double min,
                                 bool min_inclusive, double max, bool max_inclusive) const {
  std::string allowed = "must be a finite number ";
  if (std::isinf(max)) {
    allowed += (min_inclusive ? ">= " : "> ") + number_text(min);
  } else {
    allowed += std::string("in ") + (min_inclusive ? "[" : "(") + number_text(min) + ", " +
               number_text(max) + (max_inclusive ? "]" : ")");
  }
  double value = 0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value))
    fail(node, path, allowed + ", got " + shown(node));
  const bool above_min = min_inclusive ? value >= min : value > min;
  const bool below_max = max_inclusive ? value <= max : value < max;
  if (!above_min || !below_max) fail(node, path, allowed + ", got " + number_text(value));
  return value;
}

bool YamlReader::read_bool(const YAML::Node &node, const std::string &path) const {
  bool value = false;
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value))
    fail(node, path, "must be true or false, got " + shown(node));
  return value;
}

std::string YamlReader::read_string(const YAML::Node &node, const std::string &path) const {
  if (!node.IsScalar() || node.Scalar().empty())
    fail(node, path, "must be a non-empty string, got " + shown(node));
  // A NUL ("\0" in a double-quoted YAML string) would end the name at the operating system
  // (every step's file would be the same truncated path): never a usable file name or name.
  const std::string &value = node.Scalar();
  if (const size_t nul = value.find('\0'); nul != std::string::npos)
    fail(node, path,
         "contains a NUL character (\\0) at byte " + std::to_string(nul) + " of " +
             quoted_text(value) + "; remove it");
  return value;
}

std::string YamlReader::read_choice(const YAML::Node &node, const std::string &path,
                                    const std::vector<std::string> &allowed) const {
  const std::string one_of = "must be one of " + join(allowed, ", ");
  if (!node.IsScalar()) fail(node, path, one_of + "; got " + shown(node));
  const std::string value = node.Scalar();
  for (const std::string &candidate : allowed)
    if (candidate == value) return value;
  fail(node, path,
       one_of + "; got " + quoted_text(value) + " (did you mean '" + nearest_key(value, allowed) +
           "'?)");
}

std::array<double, 3> YamlReader::read_vec3(const YAML::Node &node, const std::string &path) const {
  if (!node.IsSequence() || node.size() != 3)
    fail(node, path, "must be a list of 3 finite numbers [x, y, z], got " + shown(node));
  std::array<double, 3> v{};
  for (size_t i = 0; i < 3; ++i) v[i] = read_finite(node[i], index_path(path, i));
  return v;
}

std::array<double, 3> YamlReader::read_rgb(const YAML::Node &node, const std::string &path) const {
  if (!node.IsSequence() || node.size() != 3)
    fail(node, path, "must be a color [r, g, b] with components in [0, 1], got " + shown(node));
  std::array<double, 3> rgb{};
  for (size_t i = 0; i < 3; ++i)
    rgb[i] = read_in_range(node[i], index_path(path, i), 0.0, true, 1.0, true);
  return rgb;
}

}  // namespace lantern
