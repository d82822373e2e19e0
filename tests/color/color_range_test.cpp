// Remembered scalar ranges (color.range): frame, first, running, fixed, and a change of mode.
#include <gtest/gtest.h>

#include <array>
#include <optional>

#include "core/color/color_range.h"

namespace lantern {
namespace {

using Range = std::optional<std::array<double, 2>>;

std::vector<Range> run(ColorConfig config, const std::vector<Range> &frames) {
  ColorRange memory;
  std::vector<Range> out;
  for (const Range &f : frames) out.push_back(memory.update(config, f));
  return out;
}

const std::vector<Range> kFrames = {std::nullopt, Range({{0, 1}}), Range({{-1, 3}}),
                                    Range({{0.5, 1}}), std::nullopt};

TEST(ColorRange, FrameFollowsEachFrame) {
  EXPECT_EQ(run(ColorConfig{}, kFrames), kFrames);
}

TEST(ColorRange, FirstKeepsTheFirstRangeSeen) {
  ColorConfig c;
  c.auto_range = AutoRange::kFirst;
  const std::vector<Range> expected = {std::nullopt, Range({{0, 1}}), Range({{0, 1}}),
                                       Range({{0, 1}}), Range({{0, 1}})};
  EXPECT_EQ(run(c, kFrames), expected);
}

TEST(ColorRange, RunningIsTheUnionSoFar) {
  ColorConfig c;
  c.auto_range = AutoRange::kRunning;
  const std::vector<Range> expected = {std::nullopt, Range({{0, 1}}), Range({{-1, 3}}),
                                       Range({{-1, 3}}), Range({{-1, 3}})};
  EXPECT_EQ(run(c, kFrames), expected);
}

TEST(ColorRange, AFixedRangeWinsAndAChangeOfModeStartsOver) {
  ColorConfig c;
  c.range = std::array<double, 2>{2, 5};
  EXPECT_EQ(run(c, kFrames), std::vector<Range>(kFrames.size(), Range({{2, 5}})));
  ColorRange memory;
  c.range.reset();
  c.auto_range = AutoRange::kRunning;
  memory.update(c, Range({{0, 10}}));
  c.auto_range = AutoRange::kFirst;
  EXPECT_EQ(memory.update(c, Range({{1, 2}})), Range({{1, 2}}));
  EXPECT_EQ(memory.current(), Range({{1, 2}}));
}

}  // namespace
}  // namespace lantern
