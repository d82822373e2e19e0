#include "core/config/file_pattern.h"

#include <gtest/gtest.h>

#include "tests/support/status_expect.h"

namespace lantern {
namespace {

TEST(FilePattern, Step) {
  EXPECT_EQ(expand_pattern("f_{step}.png", 42, "s"), "f_42.png");
  EXPECT_EQ(expand_pattern("f_{step}.png", 0, "s"), "f_0.png");
}

TEST(FilePattern, ZeroPaddedStepOfAnyWidth) {
  EXPECT_EQ(expand_pattern("out/frame_{step:06d}.png", 42, "s"), "out/frame_000042.png");
  EXPECT_EQ(expand_pattern("{step:01d}", 42, "s"), "42");
  EXPECT_EQ(expand_pattern("{step:03d}", 123456, "s"), "123456");  // never truncated
  EXPECT_EQ(expand_pattern("{step:12d}", 7, "s"), "{step:12d}");   // not a valid placeholder
  EXPECT_EQ(expand_pattern("{step:012d}", 7, "s"), "000000000007");
  EXPECT_EQ(expand_pattern("{step:020d}", 9223372036854775807LL, "s"), "09223372036854775807");
}

TEST(FilePattern, SceneAndSeveralPlaceholders) {
  EXPECT_EQ(expand_pattern("{scene}/{scene}_{step:04d}.exr", 5, "top"), "top/top_0005.exr");
  EXPECT_TRUE(pattern_uses_scene("{scene}.png"));
  EXPECT_FALSE(pattern_uses_scene("x_{step}.png"));
}

TEST(FilePattern, EscapedBraces) {
  EXPECT_OK(validate_pattern("a{{b}}_{step}.png"));
  EXPECT_EQ(expand_pattern("a{{b}}_{step}.png", 1, "s"), "a{b}_1.png");
}

TEST(FilePattern, ValidPatterns) {
  for (const char *p : {"a.png", "{step}", "{step:06d}", "{scene}", "x/{scene}/{step:01d}.tif"})
    EXPECT_OK(validate_pattern(p)) << p;
}

TEST(FilePattern, InvalidPatternsAreNamed) {
  const auto contains = [](const Status &s, const std::string &part) {
    return s.code == StatusCode::kConfig && s.message.find(part) != std::string::npos;
  };
  EXPECT_TRUE(contains(validate_pattern("f_{stp}.png"), "{stp}"));
  EXPECT_TRUE(contains(validate_pattern("f_{step:6d}.png"), "{step:6d}"));
  EXPECT_TRUE(contains(validate_pattern("f_{step:06x}.png"), "{step:06x}"));
  EXPECT_TRUE(contains(validate_pattern("f_{step:021d}.png"), "{step:021d}"));
  EXPECT_TRUE(contains(validate_pattern("f_{}.png"), "{}"));
  EXPECT_TRUE(contains(validate_pattern("f_{step.png"), "unclosed"));
  EXPECT_TRUE(contains(validate_pattern("f_step}.png"), "unmatched"));
  EXPECT_FALSE(validate_pattern("").ok());
}

}  // namespace
}  // namespace lantern
