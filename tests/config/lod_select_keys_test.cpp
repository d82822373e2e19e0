// lod.select: uniform by default, nearest on request, anything else refused
// naming key, line and the allowed words.
#include <gtest/gtest.h>

#include "core/config/config_loader.h"
#include "tests/support/config_error_expect.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::expect_config_error;

TEST(LodSelectKeys, UniformByDefaultNearestOnRequest) {
  Config c;
  ASSERT_OK(load_config("scenes:\n  - lod: {fraction: 0.25}\n", &c));
  EXPECT_EQ(c.scenes[0].lod.select, LodSelect::kUniform);
  ASSERT_OK(load_config("scenes:\n  - lod: {fraction: 0.25, select: nearest}\n", &c));
  EXPECT_EQ(c.scenes[0].lod.select, LodSelect::kNearest);
  ASSERT_OK(load_config("scenes:\n  - lod: {select: uniform}\n", &c));
  EXPECT_EQ(c.scenes[0].lod.select, LodSelect::kUniform);
}

TEST(LodSelectKeys, AnythingElseIsRefused) {
  expect_config_error(
      "scenes:\n  - lod: {fraction: 0.5, select: nearst}\n",
      {"scenes[0].lod.select", "line 2", "uniform, nearest", "did you mean 'nearest'?"});
  expect_config_error("scenes:\n  - name: a\n  - lod:\n      select: 3\n",
                      {"scenes[1].lod.select", "line 4", "uniform, nearest"});
  expect_config_error("scenes:\n  - lod: {select: [nearest]}\n",
                      {"scenes[0].lod.select", "uniform, nearest"});
}

}  // namespace
}  // namespace lantern
