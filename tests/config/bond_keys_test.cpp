// The bonds keys (a scene's `bonds:` section): absent = no bonds, present = bonds with the
// defaults, given values read, bad values rejected naming key, line and range; no bonds with
// style: density.
#include <gtest/gtest.h>

#include <string>

#include "core/config/config_loader.h"
#include "tests/support/config_error_expect.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::expect_config_error;

TEST(BondKeys, AbsentIsOffAndAnEmptySectionIsTheDefaults) {
  Config c;
  ASSERT_OK(load_config("scenes:\n  - name: a\n", &c));
  EXPECT_FALSE(c.scenes[0].bonds.enabled);
  for (const char *doc : {"scenes:\n  - bonds: {}\n", "scenes:\n  - bonds:\n"}) {
    ASSERT_OK(load_config(doc, &c));
    const BondsConfig &b = c.scenes[0].bonds;
    EXPECT_TRUE(b.enabled) << doc;
    EXPECT_EQ(b.radius, 0.15);
    EXPECT_EQ(b.color, BondColorBy::kAtom);
    EXPECT_EQ(b.solid, (std::array<double, 3>{0.6, 0.6, 0.6}));
    EXPECT_TRUE(b.palette.empty());
  }
}

TEST(BondKeys, GivenValuesAreRead) {
  Config c;
  ASSERT_OK(load_config(
      "scenes:\n  - bonds: {radius: 0.3, color: by_type, solid: [1, 0, 0], "
      "palette: [[0, 1, 0], [0, 0, 1]]}\n    output: {pattern: '{scene}.png'}\n  - name: b\n"
      "    bonds: {color: solid}\n    output: {pattern: '{scene}.png'}\n",
      &c));
  const BondsConfig &b = c.scenes[0].bonds;
  EXPECT_EQ(b.radius, 0.3);
  EXPECT_EQ(b.color, BondColorBy::kType);
  EXPECT_EQ(b.solid, (std::array<double, 3>{1, 0, 0}));
  ASSERT_EQ(b.palette.size(), 2u);
  EXPECT_EQ(b.palette[1], (std::array<double, 3>{0, 0, 1}));
  EXPECT_EQ(c.scenes[1].bonds.color, BondColorBy::kSolid);
}

TEST(BondKeys, BadValuesNameKeyLineAndRange) {
  expect_config_error("scenes:\n  - bonds: {radius: 0}\n",
                      {"scenes[0].bonds.radius", "line 2", "> 0"});
  expect_config_error("scenes:\n  - name: a\n    bonds: {color: by_charge}\n",
                      {"scenes[0].bonds.color", "line 3", "by_atom", "by_type", "solid"});
  expect_config_error("scenes:\n  - bonds: {solid: [2, 0, 0]}\n", {"scenes[0].bonds.solid"});
  expect_config_error("scenes:\n  - bonds: {palette: []}\n",
                      {"scenes[0].bonds.palette", "at least one color"});
  expect_config_error("scenes:\n  - bonds: 0.2\n", {"scenes[0].bonds", "line 2", "mapping"});
  expect_config_error("scenes:\n  - bonds: {raduis: 0.2}\n",
                      {"bonds.raduis", "did you mean 'radius'?"});
  expect_config_error("scenes:\n  - style: density\n    bonds: {}\n",
                      {"scenes[0].bonds", "line 3", "style: spheres"});
}

}  // namespace
}  // namespace lantern
