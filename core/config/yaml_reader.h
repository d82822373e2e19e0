// Typed, validated reads from a yaml-cpp tree, with errors that name the key, its line and its
// path (e.g. "config.yaml line 7: scenes[0].camera.azimth: unknown key ...").
//
// Internal to the configuration loader: failures throw ConfigError, which load_config() catches
// and turns into its returned message, so no exception leaves core/config. Not thread-safe per
// instance; instances are cheap and short-lived.
#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace lantern {

// A fully formatted configuration error message.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class YamlReader {
 public:
  // `source` names the document in messages: the file path, or "inline config".
  explicit YamlReader(std::string source) : source_(std::move(source)) {}

  // Throws ConfigError "<source> line L: <path>: <what>" (line from `where`, 1-based; omitted
  // when yaml-cpp has no position for the node).
  [[noreturn]] void fail(const YAML::Node &where, const std::string &path,
                         const std::string &what) const;

  // Where each key of the schema lives ("azimuth" -> {"camera"}), so an unknown key that is valid
  // elsewhere gets "(azimuth is a key of camera)" in its message.
  void set_key_homes(std::map<std::string, std::vector<std::string>> homes) {
    key_homes_ = std::move(homes);
  }

  // Checks that `node` is a mapping (null counts as empty) whose keys are all in `allowed` and
  // appear once; an unknown key fails with the nearest valid key.
  void check_map(const YAML::Node &node, const std::string &path,
                 const std::vector<std::string> &allowed) const;
  void check_sequence(const YAML::Node &node, const std::string &path) const;

  // Scalar reads; `path` names the key in messages. Ranges are inclusive.
  int64_t read_int(const YAML::Node &node, const std::string &path, int64_t lo, int64_t hi) const;
  double read_finite(const YAML::Node &node, const std::string &path) const;
  // A finite number with min < value (or <= when min_inclusive) and value < max (or <=).
  double read_in_range(const YAML::Node &node, const std::string &path, double min,
                       bool min_inclusive, double max, bool max_inclusive) const;
  bool read_bool(const YAML::Node &node, const std::string &path) const;
  std::string read_string(const YAML::Node &node, const std::string &path) const;
  // One of `allowed` (exact, lower case); fails listing the allowed values.
  std::string read_choice(const YAML::Node &node, const std::string &path,
                          const std::vector<std::string> &allowed) const;
  // A list of exactly 3 finite numbers.
  std::array<double, 3> read_vec3(const YAML::Node &node, const std::string &path) const;
  // A list of 3 numbers each in [0, 1].
  std::array<double, 3> read_rgb(const YAML::Node &node, const std::string &path) const;

 private:
  std::string unknown_key_text(const std::string &key,
                               const std::vector<std::string> &allowed) const;

  std::string source_;
  std::map<std::string, std::vector<std::string>> key_homes_;
};

// "scenes[0].camera" + "fov" -> "scenes[0].camera.fov"; "" + "scenes" -> "scenes".
std::string child_path(const std::string &parent, const std::string &key);
// "scenes" + 2 -> "scenes[2]".
std::string index_path(const std::string &parent, size_t index);

}  // namespace lantern
