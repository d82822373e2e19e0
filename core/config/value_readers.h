// The value readers of the key tables (key_table.h): each turns a key's YAML value into a C++
// value or fails with a message that names the key and what it allows (YamlReader's messages).
// A reader is a callable (const YamlReader &, const YAML::Node &value, const std::string &path)
// -> value; one that returns an empty std::optional leaves the field at its default.
//
// Internal to core/config; constant data only, thread-safe.
#pragma once

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/config/enum_names.h"
#include "core/config/yaml_reader.h"

namespace lantern::value_readers {

inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr int64_t kMaxInt = std::numeric_limits<int64_t>::max();

// An integer in lo..hi.
inline auto integer(int64_t lo, int64_t hi) {
  return [lo, hi](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    return r.read_int(n, p, lo, hi);
  };
}

// A finite number in an interval written as in mathematics: number_in('(', 0, 1, ']') is
// 0 < x <= 1; an infinite end is open.
inline auto number_in(char open, double min, double max, char close) {
  return [open, min, max, close](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    return r.read_in_range(n, p, min, open == '[', max, close == ']');
  };
}
inline auto above(double min) {
  return number_in('(', min, kInf, ')');
}
inline auto at_least(double min) {
  return number_in('[', min, kInf, ')');
}

inline auto finite() {
  return [](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    return r.read_finite(n, p);
  };
}

inline auto boolean() {
  return [](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    return r.read_bool(n, p);
  };
}

// A non-empty string without NUL characters.
inline auto text() {
  return [](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    return r.read_string(n, p);
  };
}

// One of the words, as written.
inline auto one_of(std::vector<std::string> words) {
  return [words = std::move(words)](const YamlReader &r, const YAML::Node &n,
                                    const std::string &p) { return r.read_choice(n, p, words); };
}

// One of the words, as the value paired with it: one_of<bool>({{"half", true}, {"float", false}}).
template <typename V>
auto one_of(std::vector<std::pair<std::string, V>> words) {
  std::vector<std::string> names;
  for (const auto &word : words) names.push_back(word.first);
  return [words = std::move(words), names = std::move(names)](
             const YamlReader &r, const YAML::Node &n, const std::string &p) {
    const std::string word = r.read_choice(n, p, names);
    return std::find_if(words.begin(), words.end(), [&](const auto &w) { return w.first == word; })
        ->second;
  };
}

// A configuration enum, by the names of its table in enum_names.h: one_of<Projection>().
template <typename E>
auto one_of() {
  return [](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    return *value_of<E>(r.read_choice(n, p, names_of<E>()));
  };
}

// [x, y, z], finite.
inline auto vec3() {
  return [](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    return r.read_vec3(n, p);
  };
}
inline auto nonzero_vec3() {
  return [](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    const std::array<double, 3> v = r.read_vec3(n, p);
    if (v == std::array<double, 3>{0, 0, 0}) r.fail(n, p, "must not be the zero vector");
    return v;
  };
}
// [r, g, b], each in [0, 1].
inline auto rgb() {
  return [](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    return r.read_rgb(n, p);
  };
}

// A list of values; `empty_message`, when given, refuses an empty list with it.
template <typename Read>
auto list_of(Read read, const char *empty_message = nullptr) {
  return [read, empty_message](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    r.check_sequence(n, p);
    if (empty_message != nullptr && n.size() == 0) r.fail(n, p, empty_message);
    std::vector<decltype(read(r, n, p))> values;
    for (size_t i = 0; i < n.size(); ++i) values.push_back(read(r, n[i], index_path(p, i)));
    return values;
  };
}

// A list of words, none of them twice.
template <typename Read>
auto distinct_list_of(Read read) {
  return [read](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    r.check_sequence(n, p);
    std::vector<std::string> words;
    for (size_t i = 0; i < n.size(); ++i) {
      const std::string word = read(r, n[i], index_path(p, i));
      if (std::find(words.begin(), words.end(), word) != words.end())
        r.fail(n[i], index_path(p, i), "'" + word + "' is listed twice");
      words.push_back(word);
    }
    return words;
  };
}

// A list read by `read`, sorted, each value once.
template <typename Read>
auto sorted_set_of(Read read) {
  return [read](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    auto values = read(r, n, p);
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
    return values;
  };
}

// `word` (e.g. "auto") keeps the field's default; anything else is read by `read`.
template <typename Read>
auto default_if(std::string word, Read read) {
  return [word = std::move(word), read](const YamlReader &r, const YAML::Node &n,
                                        const std::string &p) {
    using Value = decltype(read(r, n, p));
    if (n.IsScalar() && n.Scalar() == word) return std::optional<Value>();
    return std::optional<Value>(read(r, n, p));
  };
}

// 'auto' (the default) or [lo, hi] with lo < hi; `lo` and `hi` name the ends in the message.
inline auto auto_or_range(const std::string &lo, const std::string &hi) {
  const std::string allowed = "must be 'auto' or [" + lo + ", " + hi + "] with " + lo + " < " + hi;
  return [allowed](const YamlReader &r, const YAML::Node &n, const std::string &p) {
    using Range = std::optional<std::array<double, 2>>;
    if (n.IsScalar() && n.Scalar() == "auto") return Range();
    if (!n.IsSequence() || n.size() != 2) r.fail(n, p, allowed);
    const double min = r.read_finite(n[0], index_path(p, 0));
    const double max = r.read_finite(n[1], index_path(p, 1));
    if (!(min < max)) r.fail(n, p, allowed);
    return Range(std::array<double, 2>{min, max});
  };
}

}  // namespace lantern::value_readers
