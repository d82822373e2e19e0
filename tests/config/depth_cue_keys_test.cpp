// The depth-cue keys: off by default, bare sections on with defaults, and bad values
// rejected naming key, line and the allowed range.
#include <gtest/gtest.h>

#include <string>

#include "core/config/config_loader.h"
#include "tests/support/config_error_expect.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::expect_config_error;

TEST(DepthCueKeys, EveryCueIsOffByDefault) {
  Config c;
  ASSERT_OK(load_config("scenes:\n  - name: a\n", &c));
  EXPECT_FALSE(c.scenes[0].ambient_occlusion.enabled);
  EXPECT_FALSE(c.scenes[0].outline.enabled);
  EXPECT_FALSE(c.scenes[0].depth_cue.enabled);
  EXPECT_TRUE(c.scenes[0].opacity.empty());
}

TEST(DepthCueKeys, OpacityIsAListPerType) {
  Config c;
  ASSERT_OK(load_config("scenes:\n  - opacity: [0.5, 1, 0]\n", &c));
  EXPECT_EQ(c.scenes[0].opacity, (std::vector<double>{0.5, 1.0, 0.0}));
}

TEST(DepthCueKeys, BareSectionsTurnTheCuesOnWithDefaults) {
  Config c;
  ASSERT_OK(load_config(
      "scenes:\n  - ambient_occlusion: {method: screen}\n    outline: {}\n    depth_cue:\n", &c));
  const SceneConfig &s = c.scenes[0];
  EXPECT_TRUE(s.ambient_occlusion.enabled);
  EXPECT_EQ(s.ambient_occlusion.method, AmbientOcclusionMethod::kScreen);
  EXPECT_FALSE(s.ambient_occlusion.radius.has_value());
  EXPECT_EQ(s.ambient_occlusion.samples, 16);
  EXPECT_EQ(s.ambient_occlusion.resolution, AoResolution::kHalf);
  EXPECT_EQ(s.ambient_occlusion.max_nodes, kDefaultAoMaxNodes);
  EXPECT_EQ(kDefaultAoMaxNodes, 262144);
  EXPECT_TRUE(s.outline.enabled);
  EXPECT_EQ(s.outline.width, 1);
  EXPECT_EQ(s.outline.depth_threshold, 1.0);
  EXPECT_TRUE(s.depth_cue.enabled);
  EXPECT_FALSE(s.depth_cue.start || s.depth_cue.end || s.depth_cue.color);
}

TEST(DepthCueKeys, GivenValuesAreRead) {
  Config c;
  ASSERT_OK(
      load_config("scenes:\n"
                  "  - ambient_occlusion: {method: screen, radius: 2.5, samples: 32, "
                  "strength: 0.25, resolution: full, max_nodes: 1000000}\n"
                  "    outline: {width: 3, color: [1, 0, 0], depth_threshold: 0.5}\n"
                  "    depth_cue: {start: 5, end: 9, color: [0, 0, 1]}\n",
                  &c));
  const SceneConfig &s = c.scenes[0];
  EXPECT_EQ(*s.ambient_occlusion.radius, 2.5);
  EXPECT_EQ(s.ambient_occlusion.samples, 32);
  EXPECT_EQ(s.ambient_occlusion.strength, 0.25);
  EXPECT_EQ(s.ambient_occlusion.resolution, AoResolution::kFull);
  EXPECT_EQ(s.ambient_occlusion.max_nodes, 1000000);
  EXPECT_EQ(s.outline.width, 3);
  EXPECT_EQ(s.outline.color, (std::array<double, 3>{1, 0, 0}));
  EXPECT_EQ(s.outline.depth_threshold, 0.5);
  EXPECT_EQ(*s.depth_cue.start, 5.0);
  EXPECT_EQ(*s.depth_cue.end, 9.0);
  EXPECT_EQ(*s.depth_cue.color, (std::array<double, 3>{0, 0, 1}));
}

TEST(DepthCueKeys, BadValuesNameKeyLineAndRange) {
  expect_config_error("scenes:\n  - ambient_occlusion: {radius: -1}\n",
                      {"scenes[0].ambient_occlusion.radius", "line 2", "> 0"});
  expect_config_error("scenes:\n  - name: a\n    ambient_occlusion: {strength: 1.5}\n",
                      {"scenes[0].ambient_occlusion.strength", "line 3", "in [0, 1]"});
  expect_config_error("scenes:\n  - ambient_occlusion: {strength: -0.1}\n",
                      {"ambient_occlusion.strength", "in [0, 1]"});
  expect_config_error("scenes:\n  - ambient_occlusion: {samples: 0}\n",
                      {"scenes[0].ambient_occlusion.samples", "line 2", "64"});
  expect_config_error("scenes:\n  - ambient_occlusion: {samples: 65}\n",
                      {"ambient_occlusion.samples", "64"});
  expect_config_error("scenes:\n  - ambient_occlusion: {method: volume}\n",
                      {"scenes[0].ambient_occlusion.method", "line 2", "screen", "object"});
  expect_config_error("scenes:\n  - ambient_occlusion: {resolution: quarter}\n",
                      {"scenes[0].ambient_occlusion.resolution", "line 2", "half", "full"});
  expect_config_error("scenes:\n  - ambient_occlusion: {method: object, max_nodes: 63}\n",
                      {"scenes[0].ambient_occlusion.max_nodes", "line 2", "64", "4194304"});
  expect_config_error("scenes:\n  - ambient_occlusion: {max_nodes: 4194305}\n",
                      {"scenes[0].ambient_occlusion.max_nodes", "4194304"});
  expect_config_error("scenes:\n  - ambient_occlusion: {max_nodes: 1.5e5}\n",
                      {"scenes[0].ambient_occlusion.max_nodes", "integer"});
  expect_config_error("scenes:\n  - ambient_occlusion: {max_nodes: lots}\n",
                      {"scenes[0].ambient_occlusion.max_nodes"});
  expect_config_error("scenes:\n  - outline: {width: 0}\n",
                      {"scenes[0].outline.width", "line 2", "16"});
  expect_config_error("scenes:\n  - outline: {depth_threshold: -1}\n",
                      {"scenes[0].outline.depth_threshold", ">= 0"});
  expect_config_error("scenes:\n  - outline: {color: [2, 0, 0]}\n", {"scenes[0].outline.color"});
  expect_config_error("scenes:\n  - depth_cue: {start: 5, end: 3}\n",
                      {"scenes[0].depth_cue.end", "line 2", "> 5"});
  expect_config_error("scenes:\n  - depth_cue: {start: -1}\n",
                      {"scenes[0].depth_cue.start", ">= 0"});
  expect_config_error("scenes:\n  - outline: 3\n", {"scenes[0].outline", "line 2", "mapping"});
  expect_config_error("scenes:\n  - outline: {widht: 3}\n",
                      {"outline.widht", "did you mean 'width'?"});
  expect_config_error("scenes:\n  - opacity: [1, 1.5]\n",
                      {"scenes[0].opacity[1]", "line 2", "in [0, 1]", "1.5"});
  expect_config_error("scenes:\n  - opacity: [-0.5]\n", {"scenes[0].opacity[0]", "in [0, 1]"});
  expect_config_error("scenes:\n  - opacity: []\n", {"scenes[0].opacity", "at least one"});
}

}  // namespace
}  // namespace lantern
