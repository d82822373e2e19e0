// style: density and its density: section - defaults, accepted values, and the errors (key, line,
// path and the allowed values).
#include <gtest/gtest.h>

#include <string>

#include "core/config/config_loader.h"
#include "tests/support/config_error_expect.h"

namespace lantern {
namespace {

using testing::expect_config_error;

TEST(DensityConfig, DefaultsLeaveSpheres) {
  Config c;
  ASSERT_TRUE(load_config("scenes:\n  - name: a\n", &c).ok());
  EXPECT_EQ(c.scenes[0].style, SceneStyle::kSpheres);
  EXPECT_EQ(c.scenes[0].density.transfer, DensityTransfer::kLinear);
  EXPECT_FALSE(c.scenes[0].density.range.has_value());
  EXPECT_EQ(c.scenes[0].density.colormap, "grayscale");
}

TEST(DensityConfig, ReadsEveryKey) {
  Config c;
  const Status s = load_config(
      "scenes:\n  - style: density\n    density: {transfer: log, range: [0.5, 20], colormap: "
      "plasma}\n",
      &c);
  ASSERT_TRUE(s.ok()) << s.message;
  EXPECT_EQ(c.scenes[0].style, SceneStyle::kDensity);
  EXPECT_EQ(c.scenes[0].density.transfer, DensityTransfer::kLog);
  ASSERT_TRUE(c.scenes[0].density.range.has_value());
  EXPECT_EQ((*c.scenes[0].density.range)[0], 0.5);
  EXPECT_EQ((*c.scenes[0].density.range)[1], 20.0);
  EXPECT_EQ(c.scenes[0].density.colormap, "plasma");
  ASSERT_TRUE(load_config("scenes:\n  - density: {transfer: asinh, range: auto}\n", &c).ok());
  EXPECT_EQ(c.scenes[0].density.transfer, DensityTransfer::kAsinh);
  EXPECT_FALSE(c.scenes[0].density.range.has_value());
}

TEST(DensityConfig, BadValuesNameKeyLineAndChoices) {
  expect_config_error("scenes:\n  - name: a\n    style: densty\n",
                      {"scenes[0].style", "line 3", "spheres, density", "did you mean 'density'?"});
  expect_config_error("scenes:\n  - density: {transfer: sqrt}\n",
                      {"scenes[0].density.transfer", "line 2", "linear, log, asinh"});
  expect_config_error("scenes:\n  - density: {colormap: jet}\n",
                      {"scenes[0].density.colormap", "line 2", "viridis, plasma, inferno"});
  expect_config_error("scenes:\n  - density: {range: [3, 1]}\n",
                      {"scenes[0].density.range", "lo < hi"});
  expect_config_error("scenes:\n  - density: {transfer: log, range: [0, 10]}\n",
                      {"scenes[0].density.range", "line 2", "lo > 0"});
  expect_config_error("scenes:\n  - density: {transfer: log, range: [-2, 10]}\n",
                      {"scenes[0].density.range", "lo > 0"});
  expect_config_error("scenes:\n  - density: {gain: 2}\n", {"scenes[0].density", "gain"});
  expect_config_error("scenes:\n  - style: density\n    lod: {fraction: 0}\n",
                      {"scenes[0].lod.fraction", "line 3", "(0, 1]"});
  expect_config_error("scenes:\n  - style: density\n    lod: {fraction: 1.01}\n",
                      {"scenes[0].lod.fraction", "(0, 1]"});
}

// Keys that need depth or sharp edges are refused with style: density, not silently ignored.
TEST(DensityConfig, SuperSamplingAndDepthCuesAreRefusedWithDensity) {
  expect_config_error("scenes:\n  - style: density\n    samples: 4\n",
                      {"scenes[0].samples", "line 3", "allowed: 1"});
  for (const char *cue : {"ambient_occlusion", "outline", "depth_cue"})
    expect_config_error(std::string("scenes:\n  - style: density\n    ") + cue + ": {}\n",
                        {"line 3", cue, "needs style: spheres"});
  Config c;
  EXPECT_TRUE(load_config("scenes:\n  - style: density\n    samples: 1\n", &c).ok());
}

}  // namespace
}  // namespace lantern
