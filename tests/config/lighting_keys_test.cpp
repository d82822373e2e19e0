// The lighting keys (core/config/lighting.h): absent = the default headlight, given
// values read (the direction normalised), bad values rejected naming key, line and range.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/config/config_loader.h"
#include "tests/support/config_error_expect.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::expect_config_error;

TEST(LightingKeys, AbsentOrEmptyIsTheDefaultHeadlight) {
  for (const char *doc :
       {"scenes:\n  - name: a\n", "scenes:\n  - lighting: {}\n", "scenes:\n  - lighting:\n"}) {
    Config c;
    ASSERT_OK(load_config(doc, &c));
    const Lighting &l = c.scenes[0].lighting;
    EXPECT_TRUE(l.is_default()) << doc;
    EXPECT_TRUE(l.headlight()) << doc;
    EXPECT_EQ(l.ambient, 0.2);
    EXPECT_EQ(l.diffuse, 0.8);
    EXPECT_EQ(l.specular, 0.3);
    EXPECT_EQ(l.shininess, 40.0);
  }
}

TEST(LightingKeys, GivenValuesAreReadAndTheDirectionNormalised) {
  Config c;
  ASSERT_OK(load_config(
      "scenes:\n  - lighting: {direction: [3, 0, 4], ambient: 0.1, diffuse: 1, specular: 0, "
      "shininess: 512}\n",
      &c));
  const Lighting &l = c.scenes[0].lighting;
  EXPECT_DOUBLE_EQ(l.direction[0], 0.6);
  EXPECT_EQ(l.direction[1], 0.0);
  EXPECT_DOUBLE_EQ(l.direction[2], 0.8);
  EXPECT_EQ(l.ambient, 0.1);
  EXPECT_EQ(l.diffuse, 1.0);
  EXPECT_EQ(l.specular, 0.0);
  EXPECT_EQ(l.shininess, 512.0);
  EXPECT_FALSE(l.is_default());
  EXPECT_FALSE(l.headlight());
  // Any positive length of +z is the headlight exactly.
  ASSERT_OK(load_config("scenes:\n  - lighting: {direction: [0, 0, 7]}\n", &c));
  EXPECT_TRUE(c.scenes[0].lighting.is_default());
}

TEST(LightingKeys, BadValuesNameKeyLineAndRange) {
  expect_config_error("scenes:\n  - lighting: {direction: [0, 0, 0]}\n",
                      {"scenes[0].lighting.direction", "line 2", "non-zero"});
  expect_config_error("scenes:\n  - lighting: {direction: [1, 0]}\n",
                      {"scenes[0].lighting.direction"});
  expect_config_error("scenes:\n  - name: a\n    lighting: {ambient: 1.5}\n",
                      {"scenes[0].lighting.ambient", "line 3", "in [0, 1]", "1.5"});
  expect_config_error("scenes:\n  - lighting: {diffuse: -0.1}\n",
                      {"scenes[0].lighting.diffuse", "line 2", "in [0, 1]"});
  expect_config_error("scenes:\n  - lighting: {specular: 2}\n",
                      {"scenes[0].lighting.specular", "in [0, 1]"});
  expect_config_error("scenes:\n  - lighting: {shininess: 0.5}\n",
                      {"scenes[0].lighting.shininess", "line 2", "in [1, 1024]"});
  expect_config_error("scenes:\n  - lighting: {shininess: 2000}\n",
                      {"scenes[0].lighting.shininess", "in [1, 1024]"});
  expect_config_error("scenes:\n  - lighting: 3\n", {"scenes[0].lighting", "line 2", "mapping"});
  expect_config_error("scenes:\n  - lighting: {diffuze: 0.5}\n",
                      {"lighting.diffuze", "did you mean 'diffuse'?"});
}

}  // namespace
}  // namespace lantern
