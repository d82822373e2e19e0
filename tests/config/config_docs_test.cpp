// The documentation cannot drift from the loader: every key of every section the loader reads
// (config_sections(), from its key tables) has a row in that section's key table in
// config/README.md and a line in config/reference.yaml, and neither documents a key the loader
// does not read.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/config/config_loader.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

// Where each section's key table is in config/README.md: the line after which it comes (with
// no heading in between).
const std::map<std::string, std::string> kReadmeAnchors = {
    {"the top level", "## Top level"},
    {"schedule", "## `schedule`"},
    {"scenes[]", "## `scenes[i]`"},
    {"scenes[].camera", "### `camera`"},
    {"scenes[].camera.path[]", "#### `camera.path`: a camera that moves"},
    {"scenes[].camera.orbit", "#### `camera.orbit`: a steady turn"},
    {"scenes[].color", "### `color`"},
    {"scenes[].output", "### `output`"},
    {"scenes[].output.movie", "#### `output.movie`: a movie written while the simulation runs"},
    {"scenes[].culling", "### `culling`"},
    {"scenes[].lod", "### `lod`"},
    {"scenes[].cut_planes[]", "### `cut_planes[j]`"},
    {"scenes[].ambient_occlusion", "`ambient_occlusion`:"},
    {"scenes[].outline", "`outline`:"},
    {"scenes[].depth_cue", "`depth_cue`:"},
    {"scenes[].density", "### `style: density` and `density`"},
    {"scenes[].lighting", "### `lighting`: the light of the spheres"},
    {"scenes[].bonds", "### `bonds`: cylinders between bonded atoms"},
    {"scenes[].labels[]", "`labels[k]` (a list; several per scene):"},
    {"scenes[].legend", "`legend`:"},
    {"scenes[].box", "`box`:"},
    {"scenes[].axes", "`axes`:"},
    {"dump", "## `dump`"},
    {"lammps", "## `lammps`"},
};

std::string read_text(const std::string &path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> lines_of(const std::string &text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string listed(const std::set<std::string> &keys) {
  std::string out;
  for (const std::string &k : keys) out += (out.empty() ? "" : ", ") + k;
  return out;
}

// The keys named in the first column of the `| key | type | default | meaning |` table that
// follows the line `anchor` ("`width`, `height`" names two). Fails the test when there is none.
std::set<std::string> readme_keys(const std::vector<std::string> &lines,
                                  const std::string &anchor) {
  size_t i = 0;
  while (i < lines.size() && lines[i] != anchor) ++i;
  if (i == lines.size()) {
    ADD_FAILURE() << "config/README.md has no line '" << anchor << "'";
    return {};
  }
  for (++i; i < lines.size() && lines[i].rfind("| key |", 0) != 0; ++i) {
    if (lines[i].rfind("#", 0) == 0) {
      ADD_FAILURE() << "config/README.md: no key table between '" << anchor << "' and '" << lines[i]
                    << "'";
      return {};
    }
  }
  std::set<std::string> keys;
  const std::regex name("`([a-z_0-9]+)`");
  for (i += 2; i < lines.size() && lines[i].rfind("|", 0) == 0; ++i) {
    const std::string first_cell = lines[i].substr(1, lines[i].find('|', 1) - 1);
    for (std::sregex_iterator m(first_cell.begin(), first_cell.end(), name), end; m != end; ++m)
      keys.insert((*m)[1]);
  }
  return keys;
}

TEST(ConfigDocs, EveryKeyHasARowInItsReadmeTable) {
  const std::vector<std::string> lines =
      lines_of(read_text(std::string(LANTERN_CONFIG_DIR) + "/README.md"));
  for (const ConfigSection &section : config_sections()) {
    const auto anchor = kReadmeAnchors.find(section.label);
    if (anchor == kReadmeAnchors.end()) {
      ADD_FAILURE() << "section " << section.label
                    << " has no key table in config/README.md: write one and name the line it "
                       "follows in kReadmeAnchors";
      continue;
    }
    const std::set<std::string> documented = readme_keys(lines, anchor->second);
    const std::set<std::string> read(section.keys.begin(), section.keys.end());
    std::set<std::string> missing, extra;
    for (const std::string &k : read)
      if (documented.count(k) == 0) missing.insert(k);
    for (const std::string &k : documented)
      if (read.count(k) == 0) extra.insert(k);
    EXPECT_TRUE(missing.empty()) << section.label << ": no row in config/README.md's table after '"
                                 << anchor->second << "' for " << listed(missing);
    EXPECT_TRUE(extra.empty()) << section.label << ": config/README.md documents " << listed(extra)
                               << ", which the loader does not read";
  }
}

// reference.yaml with its commented-out keys (`# position: [0, -100, 0]`, also in a commented
// section) written in: the document with every key.
std::string reference_with_every_key() {
  const std::regex commented_key(R"(^(\s*)# ( *(- )?[a-z_]+:.*)$)");
  std::string out;
  for (const std::string &line :
       lines_of(read_text(std::string(LANTERN_CONFIG_DIR) + "/reference.yaml")))
    out += std::regex_replace(line, commented_key, "$1$2") + "\n";
  return out;
}

// The mappings a section label names in `root`: "scenes[].cut_planes[]" is every cut plane of
// every scene.
std::vector<YAML::Node> nodes_of(const YAML::Node &root, const std::string &label) {
  std::vector<YAML::Node> nodes = {root};
  if (label == "the top level") return nodes;
  std::istringstream parts(label);
  for (std::string part; std::getline(parts, part, '.');) {
    const bool list = part.size() > 2 && part.compare(part.size() - 2, 2, "[]") == 0;
    const std::string key = list ? part.substr(0, part.size() - 2) : part;
    std::vector<YAML::Node> next;
    for (const YAML::Node &node : nodes) {
      if (!node.IsMap()) continue;
      const YAML::Node child = node[key];
      if (!child.IsDefined()) continue;
      if (!list) next.push_back(child);
      if (list && child.IsSequence())
        for (const YAML::Node &element : child) next.push_back(element);
    }
    nodes.swap(next);  // never vector assignment: YAML::Node's operator= writes into the tree
  }
  return nodes;
}

TEST(ConfigDocs, ReferenceYamlWithItsCommentedKeysLoads) {
  Config config;
  EXPECT_OK(load_config_text(reference_with_every_key(), "reference.yaml, uncommented", &config));
}

TEST(ConfigDocs, EveryKeyIsInReferenceYaml) {
  const YAML::Node root = YAML::Load(reference_with_every_key());
  for (const ConfigSection &section : config_sections()) {
    const std::vector<YAML::Node> nodes = nodes_of(root, section.label);
    std::set<std::string> missing;
    for (const std::string &key : section.keys) {
      bool found = false;
      for (const YAML::Node &node : nodes) found = found || (node.IsMap() && node[key].IsDefined());
      if (!found) missing.insert(key);
    }
    EXPECT_TRUE(missing.empty()) << "config/reference.yaml has no line for " << section.label
                                 << ": " << listed(missing)
                                 << " (a commented '# key: value' line counts)";
  }
}

// The schema the documentation is checked against is the loader's own: sections and keys as
// messages name them.
TEST(ConfigDocs, SectionsAreTheLoadersOwn) {
  const std::vector<ConfigSection> sections = config_sections();
  ASSERT_FALSE(sections.empty());
  EXPECT_EQ(sections.front().label, "the top level");
  std::map<std::string, std::vector<std::string>> by_label;
  for (const ConfigSection &s : sections) by_label[s.label] = s.keys;
  EXPECT_EQ(
      by_label["scenes[].camera"],
      (std::vector<std::string>{"projection", "fov", "azimuth", "elevation", "zoom", "position",
                                "look_at", "up", "near", "far", "path", "orbit"}));
  EXPECT_EQ(by_label.count("dump.schedule"), 0u) << "dump.schedule is the top-level schedule";
  EXPECT_EQ(by_label.count("scenes[].cut_planes[]"), 1u);
}

}  // namespace
}  // namespace lantern
