// The key-table machinery on a small schema of its own with the shapes the configuration grows
// into: a list of mappings inside a section (camera: {path: [{time, position}, ...]}), an
// optional section inside a section (output: {movie: {...}}), a rule between keys, and the
// messages they give (key path, line, nearest key from the right table).
#include "core/config/key_table.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/config/value_readers.h"

namespace lantern {
namespace {

using namespace value_readers;

struct Keyframe {
  double time = 0.0;
  std::array<double, 3> position{0, 0, 0};
};
struct Camera {
  double zoom = 1.0;
  std::vector<Keyframe> path;
};
struct Movie {
  bool enabled = false;  // set when the section is present
  int fps = 25;
  std::string codec = "h264";
};
struct Output {
  std::string pattern = "frame.png";
  std::optional<Movie> movie;
};
struct Top {
  Camera camera;
  Output output;
  std::optional<double> start;  // 'auto' keeps the default
};

void path_times_increase(const YamlReader &r, const YAML::Node &camera, const std::string &path,
                         Camera &c) {
  for (size_t i = 1; i < c.path.size(); ++i)
    if (!(c.path[i].time > c.path[i - 1].time))
      r.fail(camera["path"][i], index_path(child_path(path, "path"), i),
             "time must increase along the path");
}

const Section<Keyframe> kKeyframe(
    {
        {"time", &Keyframe::time, at_least(0)},
        {"position", &Keyframe::position, vec3()},
    },
    {"each keyframe must be a mapping {time, position}"});

const Section<Camera> kCamera({
    {"zoom", &Camera::zoom, above(0)},
    {"path", &Camera::path, list_of(kKeyframe)},
    rule(path_times_increase),
});

const Section<Movie> kMovie(
    {
        {"fps", &Movie::fps, integer(1, 240)},
        {"codec", &Movie::codec, one_of({"h264", "vp9"})},
    },
    {}, &Movie::enabled);

const Section<Output> kOutput({
    {"pattern", &Output::pattern, text()},
    {"movie", &Output::movie, kMovie},
});

const Section<Top> kTop({
    {"camera", &Top::camera, kCamera},
    {"output", &Top::output, kOutput},
    {"start", &Top::start, default_if("auto", at_least(0))},
});

Top load(const std::string &document) {
  return kTop(YamlReader("test.yaml"), YAML::Load(document), "");
}

std::string error_of(const std::string &document) {
  try {
    load(document);
  } catch (const ConfigError &e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an error for: " << document;
  return "";
}

TEST(KeyTable, ListOfMappingsInsideASection) {
  const Top t = load("camera:\n  path:\n    - {time: 0, position: [1, 2, 3]}\n    - time: 2\n");
  ASSERT_EQ(t.camera.path.size(), 2u);
  EXPECT_EQ(t.camera.path[0].position, (std::array<double, 3>{1, 2, 3}));
  EXPECT_EQ(t.camera.path[1].time, 2.0);
  EXPECT_EQ(t.camera.path[1].position, (std::array<double, 3>{0, 0, 0}));  // default
  EXPECT_EQ(t.camera.zoom, 1.0);
}

TEST(KeyTable, ErrorsInsideAListNameTheElementAndLine) {
  EXPECT_EQ(error_of("camera:\n  path:\n    - time: 0\n    - time: -1\n"),
            "test.yaml line 4: camera.path[1].time: must be a finite number >= 0, got -1");
  EXPECT_EQ(error_of("camera:\n  path: [3]\n"),
            "test.yaml line 2: camera.path[0]: each keyframe must be a mapping {time, position}");
  EXPECT_EQ(error_of("camera:\n  path: {time: 1}\n"),
            "test.yaml line 2: camera.path: expected a list, got a mapping");
}

TEST(KeyTable, UnknownKeySuggestsFromItsOwnTable) {
  EXPECT_EQ(error_of("camera:\n  path:\n    - tme: 1\n"),
            "test.yaml line 3: camera.path[0].tme: unknown key 'tme'; did you mean 'time'? (valid "
            "keys: time, position)");
}

TEST(KeyTable, RuleRunsAfterTheKeysBeforeIt) {
  EXPECT_EQ(error_of("camera:\n  path:\n    - time: 2\n    - time: 1\n"),
            "test.yaml line 4: camera.path[1]: time must increase along the path");
}

TEST(KeyTable, OptionalSectionInsideASection) {
  EXPECT_FALSE(load("output: {pattern: a.png}\n").output.movie.has_value());
  EXPECT_FALSE(load("output:\n  movie:\n").output.movie.has_value()) << "no value: absent";
  const Top t = load("output:\n  movie: {fps: 30}\n");
  ASSERT_TRUE(t.output.movie.has_value());
  EXPECT_TRUE(t.output.movie->enabled);
  EXPECT_EQ(t.output.movie->fps, 30);
  EXPECT_EQ(t.output.movie->codec, "h264");
  EXPECT_EQ(error_of("output:\n  movie: {codec: h265}\n"),
            "test.yaml line 2: output.movie.codec: must be one of h264, vp9; got 'h265' (did you "
            "mean 'h264'?)");
}

TEST(KeyTable, DefaultIfKeepsTheDefault) {
  EXPECT_FALSE(load("start: auto\n").start.has_value());
  EXPECT_EQ(load("start: 3\n").start, 3.0);
  EXPECT_EQ(error_of("start: -3\n"),
            "test.yaml line 1: start: must be a finite number >= 0, got -3");
}

TEST(KeyTable, SchemaListsKeysAndTheSectionsTheyHold) {
  const std::vector<Schema::Key> keys = kCamera.keys();
  ASSERT_EQ(keys.size(), 2u);  // the rule is not a key
  EXPECT_EQ(keys[0].name, "zoom");
  EXPECT_EQ(keys[0].section, nullptr);
  EXPECT_EQ(keys[1].name, "path");
  EXPECT_EQ(keys[1].section, &kKeyframe);
  EXPECT_TRUE(keys[1].list);
  EXPECT_EQ(kOutput.keys()[1].section, &kMovie);
  EXPECT_FALSE(kOutput.keys()[1].list);
}

}  // namespace
}  // namespace lantern
