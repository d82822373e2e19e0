// A section of the configuration as a table: one entry per key - its name, the field it fills and
// the reader that checks its value (value_readers.h) - with the cross-key rules (config_rules.h)
// at the place they run. The table is the schema: a mapping's keys are checked against it, the
// nearest key is suggested from it, and the documentation test compares it with config/README.md
// and config/reference.yaml. The tables themselves are in config_loader.cpp.
//
//   const Section<LodConfig> kLod({
//       {"budget", &LodConfig::budget, integer(0, kMaxInt)},
//       {"fraction", &LodConfig::fraction, number_in('(', 0, 1, ']')},
//       {"select", &LodConfig::select, one_of<LodSelect>()},
//   });
//
// A key's value may itself be a section ({"lod", &SceneConfig::lod, kLod}) or a list of sections
// ({"cut_planes", &SceneConfig::cuts, list_of(kCutPlane)}), to any depth.
//
// Internal to core/config. Errors are thrown as ConfigError (yaml_reader.h) and caught by
// load_config(). Tables are immutable once built, so reading with them is thread-safe.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/config/yaml_reader.h"

namespace lantern {

// How a section's value is checked before its keys are read.
struct SectionShape {
  // The message for a value that is not a mapping; nullptr: YamlReader::check_map's "expected a
  // mapping with keys (...)".
  const char *not_a_map = nullptr;
  // A key with no value (`outline:`) reads as an empty mapping, the section with its defaults;
  // otherwise such a key counts as absent.
  bool null_is_empty = false;
};

// A section seen without its struct type: its keys in table order, and the sections they hold
// (for the key homes in messages and for the documentation test).
class Schema {
 public:
  struct Key {
    std::string name;
    const Schema *section;  // the section the key's value is; nullptr for a plain value
    bool list;              // a list of such sections (cut_planes: [{...}, ...])
  };

  explicit Schema(SectionShape shape) : shape_(shape) {}
  virtual ~Schema() = default;
  Schema(const Schema &) = delete;
  Schema &operator=(const Schema &) = delete;

  virtual std::vector<Key> keys() const = 0;
  const SectionShape &shape() const { return shape_; }

 private:
  SectionShape shape_;
};

// Reads a key's value (present, and not null) into the section's struct; `path` names the key.
template <typename T>
using KeyReader =
    std::function<void(const YamlReader &, const YAML::Node &, const std::string &path, T &)>;

// A check across keys of one section, run with the section's mapping and path after the entries
// before it in the table.
template <typename T>
using SectionRule = void (*)(const YamlReader &, const YAML::Node &section, const std::string &path,
                             T &);

template <typename T>
class Section;

// A list whose elements are sections: cut_planes: [{normal: ..., offset: ...}, ...].
template <typename C>
struct SectionList {
  const Section<C> *section;
  void (*init)(C &, size_t index);  // defaults that depend on the element's index, or nullptr

  std::vector<C> operator()(const YamlReader &r, const YAML::Node &node,
                            const std::string &path) const;
};

template <typename C>
SectionList<C> list_of(const Section<C> &section, void (*init)(C &, size_t index) = nullptr) {
  return {&section, init};
}

namespace key_table_detail {

template <typename V>
struct IsOptional : std::false_type {};
template <typename V>
struct IsOptional<std::optional<V>> : std::true_type {};

// A reader that returns an empty optional ("auto", "") leaves the field at its default.
template <typename F, typename V>
void assign(F &field, V &&value) {
  if constexpr (IsOptional<std::decay_t<V>>::value) {
    if (value) field = static_cast<F>(*std::forward<V>(value));
  } else {
    field = static_cast<F>(std::forward<V>(value));
  }
}

template <typename R>
Schema::Key describe(const char *key, const R &) {
  return {key, nullptr, false};
}
template <typename C>
Schema::Key describe(const char *key, const Section<C> &section) {
  return {key, &section, false};
}
template <typename C>
Schema::Key describe(const char *key, const SectionList<C> &list) {
  return {key, list.section, true};
}

// A section is read through a pointer: tables live as long as the program, and are not copied.
template <typename R>
const R &reader_of(const R &read) {
  return read;
}
template <typename C>
auto reader_of(const Section<C> &section) {
  return [section = &section](const YamlReader &r, const YAML::Node &node,
                              const std::string &path) { return (*section)(r, node, path); };
}

}  // namespace key_table_detail

// One row of a table: a key, or a rule.
template <typename T>
class Entry {
 public:
  // A key that fills one field. `field` is a member pointer, or member(...) for a field of a
  // member; `read` is a value reader (value_readers.h), a Section or a list_of(Section).
  template <typename Field, typename Read>
  Entry(const char *key, Field field, const Read &read)
      : key_(key_table_detail::describe(key, read)) {
    read_ = [field, value = key_table_detail::reader_of(read)](
                const YamlReader &r, const YAML::Node &node, const std::string &path, T &out) {
      key_table_detail::assign(std::invoke(field, out), value(r, node, path));
    };
  }
  // A key read by a function of its own: one that fills several fields, or whose range depends
  // on an earlier key (config_rules.h).
  Entry(const char *key, KeyReader<T> read) : key_{key, nullptr, false}, read_(std::move(read)) {}
  // A rule; write rule(f) in a table.
  explicit Entry(SectionRule<T> rule) : rule_(rule) {}

  bool is_key() const { return rule_ == nullptr; }
  const Schema::Key &key() const { return key_; }

  // Reads this entry's key from the section's mapping `node` (absent or null: the default
  // stays), or runs the rule.
  void apply(const YamlReader &r, const YAML::Node &node, const std::string &path, T &out) const {
    if (rule_ != nullptr) return rule_(r, node, path, out);
    if (!node.IsMap()) return;
    const YAML::Node value = node[key_.name];
    const bool null_is_empty =
        key_.section != nullptr && !key_.list && key_.section->shape().null_is_empty;
    if (!value.IsDefined() || (value.IsNull() && !null_is_empty)) return;
    read_(r, value, child_path(path, key_.name), out);
  }

 private:
  Schema::Key key_{};
  KeyReader<T> read_;
  SectionRule<T> rule_ = nullptr;
};

template <typename T>
Entry<T> rule(SectionRule<T> rule) {
  return Entry<T>(rule);
}

// The field `inner` of the member `outer`, for a key that fills a nested struct's field:
// {"confidence", member(&CullingConfig::probabilistic, &ProbabilisticConfig::confidence), ...}.
template <typename T, typename M, typename F>
auto member(M T::*outer, F M::*inner) {
  return [outer, inner](T &out) -> F & { return (out.*outer).*inner; };
}

template <typename T>
class Section : public Schema {
 public:
  // `present`: a flag set when the section is given (dump:, outline: {}), before its keys are
  // read (so a key may clear it again: dump: {enabled: false}).
  explicit Section(std::vector<Entry<T>> entries, SectionShape shape = {},
                   bool T::*present = nullptr)
      : Schema(shape), entries_(std::move(entries)), present_(present) {
    for (const Entry<T> &entry : entries_)
      if (entry.is_key()) names_.push_back(entry.key().name);
  }

  std::vector<Key> keys() const override {
    std::vector<Key> keys;
    for (const Entry<T> &entry : entries_)
      if (entry.is_key()) keys.push_back(entry.key());
    return keys;
  }

  // As a key's value: a fresh T, read from the section's mapping.
  T operator()(const YamlReader &r, const YAML::Node &node, const std::string &path) const {
    T out;
    read_into(r, node, path, out);
    return out;
  }

  // Checks `node`'s shape and keys (unknown and duplicate keys fail before any value is read),
  // then reads the given keys and runs the rules, in table order.
  void read_into(const YamlReader &r, const YAML::Node &node, const std::string &path,
                 T &out) const {
    const bool empty = node.IsNull() && shape().null_is_empty;
    if (shape().not_a_map != nullptr && !node.IsMap() && !empty)
      r.fail(node, path, shape().not_a_map);
    r.check_map(node, path, names_);
    if (present_ != nullptr) out.*present_ = true;
    for (const Entry<T> &entry : entries_) entry.apply(r, node, path, out);
  }

 private:
  std::vector<Entry<T>> entries_;
  std::vector<std::string> names_;  // the allowed keys, in table order (as messages list them)
  bool T::*present_;
};

template <typename C>
std::vector<C> SectionList<C>::operator()(const YamlReader &r, const YAML::Node &node,
                                          const std::string &path) const {
  r.check_sequence(node, path);
  std::vector<C> out;
  for (size_t i = 0; i < node.size(); ++i) {
    C element;
    if (init != nullptr) init(element, i);
    section->read_into(r, node[i], index_path(path, i), element);
    out.push_back(std::move(element));
  }
  return out;
}

}  // namespace lantern
