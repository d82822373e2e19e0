// occlusion: probabilistic through the C API: a rerun (a new context, the same step) writes the
// same bytes, another step draws other random numbers, the CPU raster serves it under
// renderer: auto, and the stats line reports the probabilistic culler's counts.
#include <fstream>

#include <nlohmann/json.hpp>

#include "tests/api/api_fixture.h"
#include "tests/support/image_file.h"

namespace lantern::testing {
namespace {

using ProbabilisticOutcome = ApiTest;

TEST_F(ProbabilisticOutcome, RerunsWriteTheSameBytesAndTheStatsLineCountsTheClasses) {
  const std::string config = scene_config(
      "p", 160, 120, "    radius: 0.6\n    culling: {occlusion: probabilistic, confidence: 0.9}\n");
  std::vector<double> x = lattice(40);  // 64,000 particles, a solid block
  lantern_particles p = interleaved(x);
  for (const int step : {7, 7, 8}) {
    ASSERT_EQ(open(config), LANTERN_OK) << message();
    ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
    ASSERT_EQ(lantern_execute(ctx_, step, 0.0), LANTERN_OK) << message();
    if (step == 7 && !std::filesystem::exists(png("first", 7)))
      std::filesystem::rename(png("p", 7), png("first", 7));
  }
  const auto first = read_bytes(png("first", 7)), again = read_bytes(png("p", 7));
  ASSERT_GT(first.size(), 1000u);
  EXPECT_EQ(first, again);

  std::ifstream stats(dir_ / "stats.jsonl");
  std::string line, last;
  while (std::getline(stats, line)) last = line;
  const auto scene = nlohmann::json::parse(last)["scenes"][0];
  EXPECT_EQ(scene["renderer"], "cpu");
  EXPECT_EQ(scene["occlusion"], "probabilistic");
  const auto &prob = scene["probabilistic"];
  EXPECT_GT(prob["iterations"].get<int64_t>(), 0);
  EXPECT_EQ(prob["samples"].get<int64_t>() % 4, 0);
  const int64_t culled = prob["particles_culled"].get<int64_t>();
  EXPECT_GT(culled, 64000 / 4);  // most of a solid block is hidden
  EXPECT_EQ(scene["particles"]["occlusion_culled"].get<int64_t>(), culled);
  EXPECT_EQ(scene["particles"]["drawn"].get<int64_t>() + culled, 64000);
  const auto &m = prob["meshlets"];
  const int64_t meshlets = m["potentially_visible"].get<int64_t>() + m["low"].get<int64_t>() +
                           m["medium"].get<int64_t>() + m["occluded"].get<int64_t>();
  EXPECT_GE(meshlets, 64000 / 16);  // 16 per meshlet, the last of a brick may hold fewer
  EXPECT_LE(meshlets, 64000 / 16 + 64);
}

}  // namespace
}  // namespace lantern::testing
