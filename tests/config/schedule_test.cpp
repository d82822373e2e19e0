#include <gtest/gtest.h>

#include "core/config/config.h"
#include "core/config/config_loader.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

TEST(Schedule, EmptyScheduleRendersEveryStep) {
  const Schedule s;
  for (int64_t step : {0, 1, 7, 1000000}) EXPECT_TRUE(s.due(step)) << step;
}

TEST(Schedule, Every) {
  Schedule s;
  s.every = 10;
  EXPECT_TRUE(s.due(0));
  EXPECT_FALSE(s.due(5));
  EXPECT_TRUE(s.due(10));
  EXPECT_TRUE(s.due(120));
  EXPECT_FALSE(s.due(121));
}

TEST(Schedule, EveryWithStart) {
  Schedule s;
  s.every = 5;
  s.start = 3;
  EXPECT_FALSE(s.due(0));
  EXPECT_TRUE(s.due(3));
  EXPECT_FALSE(s.due(5));
  EXPECT_TRUE(s.due(8));
  EXPECT_TRUE(s.due(13));
}

TEST(Schedule, ExplicitSteps) {
  Schedule s;
  s.steps = {250, 0, 100};  // unsorted on purpose: due() must not rely on order
  EXPECT_TRUE(s.due(0));
  EXPECT_TRUE(s.due(100));
  EXPECT_TRUE(s.due(250));
  EXPECT_FALSE(s.due(1));
  EXPECT_FALSE(s.due(200));
}

TEST(Schedule, EveryAndStepsIsTheUnion) {
  Schedule s;
  s.every = 100;
  s.steps = {7};
  EXPECT_TRUE(s.due(7));
  EXPECT_TRUE(s.due(300));
  EXPECT_FALSE(s.due(8));
}

TEST(Schedule, LoadedStepsAreSortedAndUnique) {
  Config c;
  ASSERT_OK(load_config("schedule: {steps: [30, 10, 30, 20]}\nscenes: [{}]\n", &c));
  EXPECT_EQ(c.schedule.steps, (std::vector<int64_t>{10, 20, 30}));
  EXPECT_TRUE(c.schedule.due(20));
  EXPECT_FALSE(c.schedule.due(0));
}

}  // namespace
}  // namespace lantern
