// budget_ms through the pipeline, at 1 and 2 ranks. A budget the full-quality frame fits gives,
// at every step, the bytes of the same scene without a budget. A budget nothing can meet draws
// full quality at the first step (to measure it), then the rung predicted cheapest on every rank
// - the bytes of those settings written out in the configuration - and says so once in the stats.
#include <gtest/gtest.h>

#include <mpi.h>

#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/pipeline/runtime.h"
#include "tests/support/image_file.h"
#include "tests/support/mpi_world.h"
#include "tests/support/one_step_render.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {
namespace {

constexpr int kSteps = 3;

// This rank's slab of a 32^3 lattice.
std::vector<double> lattice() {
  const int rank = world_rank(), ranks = world_size(), n = 32;
  std::vector<double> xyz;
  for (int z = n * rank / ranks; z < n * (rank + 1) / ranks; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) xyz.insert(xyz.end(), {double(x), double(y), double(z)});
  return xyz;
}

// The scene (4 samples, full-resolution screen AO) with `keys` added, written as `name`.
std::string config(const std::string &dir, const std::string &name, const std::string &keys,
                   const std::string &top = "") {
  return top + "gl: none\nstats: " + dir + "/" + name +
         ".jsonl\n"
         "scenes:\n"
         "  - name: " +
         name +
         "\n    width: 200\n    height: 160\n    radius: 0.6\n    renderer: cpu\n"
         "    culling: {occlusion: hzb}\n    camera: {azimuth: 35, elevation: 25}\n" +
         keys + "    output: {pattern: '" + dir + "/" + name + "_{step}.png'}\n";
}

const char kFull[] = "    samples: 4\n    ambient_occlusion: {method: screen, resolution: full}\n";

void render(const std::string &yaml) {
  std::unique_ptr<Runtime> rt;
  ASSERT_OK(Runtime::open(yaml, MPI_COMM_WORLD, &rt));
  const std::vector<double> xyz = lattice();
  ParticleDescription p{};
  p.count = int64_t(xyz.size() / 3);
  p.position = {xyz.data(), DataType::kFloat64, 0};
  ASSERT_OK(rt->publish(p));
  for (int step = 0; step < kSteps; ++step) ASSERT_OK(rt->execute(step, double(step)));
  ASSERT_OK(rt->finish());
}

std::vector<char> image(const std::string &dir, const std::string &name, int step) {
  return read_bytes(dir + "/" + name + "_" + std::to_string(step) + ".png");
}

std::vector<nlohmann::json> budget_stats(const std::string &dir, const std::string &name) {
  std::vector<nlohmann::json> out;
  std::istringstream in(read_text(dir + "/" + name + ".jsonl"));
  for (std::string line; std::getline(in, line);)
    out.push_back(nlohmann::json::parse(line)["scenes"][0].value("budget", nlohmann::json()));
  return out;
}

TEST(Budget, AFrameThatFitsIsTheFrameWithoutABudget) {
  SharedScratchDir dir("/tmp/lantern_budget_XXXXXX");
  ASSERT_FALSE(dir.path().empty());
  render(config(dir.path(), "plain", kFull));
  render(config(dir.path(), "huge", std::string(kFull) + "    budget_ms: 1.0e9\n"));
  if (world_rank() != 0) return;
  for (int step = 0; step < kSteps; ++step) {
    const auto plain = image(dir.path(), "plain", step);
    ASSERT_FALSE(plain.empty());
    EXPECT_TRUE(plain == image(dir.path(), "huge", step)) << "step " << step;
  }
  const std::vector<nlohmann::json> stats = budget_stats(dir.path(), "huge");
  ASSERT_EQ(stats.size(), size_t(kSteps));
  for (const nlohmann::json &b : stats) {
    EXPECT_EQ(b["rung"], 0) << b;
    EXPECT_EQ(b["rungs"], 9)
        << b;  // ao half, ao off, samples 1, lod 0.5 / 0.25 / 0.1 / 0.05 / 0.02
    EXPECT_EQ(b["samples"], 4);
    EXPECT_EQ(b["ambient_occlusion"], "full");
    EXPECT_TRUE(b["psnr_db"].is_null());  // exact
    EXPECT_EQ(b["unmet"], false);
    EXPECT_TRUE(b["note"].is_null());
    EXPECT_GT(b["measured_ms"].get<double>(), 0.0);
  }
  EXPECT_TRUE(budget_stats(dir.path(), "plain")[0].is_null());  // no budget, no "budget"
}

TEST(Budget, ABudgetNothingMeetsDrawsTheCheapestRungOnEveryRank) {
  SharedScratchDir dir("/tmp/lantern_budget_XXXXXX");
  ASSERT_FALSE(dir.path().empty());
  render(config(dir.path(), "full", kFull));
  render(config(dir.path(), "tiny", std::string(kFull) + "    budget_ms: 1.0e-6\n"));
  render(config(dir.path(), "cheapest", "    lod: {fraction: 0.02}\n"));
  if (world_rank() != 0) return;
  EXPECT_TRUE(image(dir.path(), "full", 0) == image(dir.path(), "tiny", 0));  // measured first
  // Step 1: nothing but rung 0 measured, the last rung is predicted cheapest.
  const auto cheapest = image(dir.path(), "cheapest", 1);
  ASSERT_FALSE(cheapest.empty());
  EXPECT_TRUE(cheapest == image(dir.path(), "tiny", 1));
  EXPECT_FALSE(cheapest == image(dir.path(), "full", 1));
  const std::vector<nlohmann::json> stats = budget_stats(dir.path(), "tiny");
  ASSERT_EQ(stats.size(), size_t(kSteps));
  EXPECT_EQ(stats[0]["rung"], 0);
  EXPECT_TRUE(stats[0]["note"].is_null());
  const nlohmann::json &b = stats[1];
  EXPECT_EQ(b["rung"], 8) << b;
  EXPECT_EQ(b["gives_up"], "lod 0.02");
  EXPECT_EQ(b["lod_fraction"], 0.02);
  EXPECT_EQ(b["samples"], 1);
  EXPECT_EQ(b["ambient_occlusion"], "off");
  EXPECT_EQ(b["unmet"], true);
  EXPECT_LT(b["psnr_db"].get<double>(), 20.0);
  EXPECT_GT(b["predicted_ms"].get<double>(), 1.0e-6);
  EXPECT_GT(b["predicted_error"].get<double>(), 0.0);
  // Said once, in the stats of the first step that cannot meet it.
  EXPECT_EQ(b["note"], "budget cannot be met: rendering at the cheapest setting");
  // Later steps draw the cheapest rung measured (which one depends on this machine's timings:
  // lod 0.02 is skipped if it was measured not cheaper than the rungs above), still unmet.
  for (int step = 2; step < kSteps; ++step) {
    const nlohmann::json &later = stats[size_t(step)];
    EXPECT_EQ(later["unmet"], true) << later;
    EXPECT_TRUE(later["note"].is_null()) << later;
    EXPECT_TRUE(later["skipped"].is_array()) << later;
  }
}

TEST(Budget, APercentOfTheRunApplesFromTheThirdStep) {
  // budget_percent: 0.0001 of the few milliseconds between steps is far less than any rung: the
  // first step is measured, the gap before the second is reduced with the second's costs, and
  // from the third step on the cheapest rung is drawn.
  SharedScratchDir dir("/tmp/lantern_budget_XXXXXX");
  ASSERT_FALSE(dir.path().empty());
  render(config(dir.path(), "full", kFull));
  render(config(dir.path(), "share", kFull, "budget_percent: 0.0001\n"));
  render(config(dir.path(), "cheapest", "    lod: {fraction: 0.02}\n"));
  if (world_rank() != 0) return;
  for (int step = 0; step < 2; ++step)
    EXPECT_TRUE(image(dir.path(), "full", step) == image(dir.path(), "share", step)) << step;
  EXPECT_TRUE(image(dir.path(), "cheapest", 2) == image(dir.path(), "share", 2));
  const std::vector<nlohmann::json> stats = budget_stats(dir.path(), "share");
  ASSERT_EQ(stats.size(), size_t(kSteps));
  EXPECT_TRUE(stats[0]["ms"].is_null());
  EXPECT_TRUE(stats[1]["ms"].is_null());
  EXPECT_GT(stats[2]["ms"].get<double>(), 0.0);
  EXPECT_EQ(stats[2]["rung"], 8);
  EXPECT_EQ(stats[2]["unmet"], true);
  EXPECT_EQ(stats[2]["note"], "budget cannot be met: rendering at the cheapest setting");
}

// Object-space occlusion on the ladder: the cheapest rung draws without it (and with one sample,
// lod 0.02), on every rank the bytes of those settings; the stats name it.
TEST(Budget, ABudgetNothingMeetsDropsObjectOcclusionOnEveryRank) {
  SharedScratchDir dir("/tmp/lantern_budget_XXXXXX");
  ASSERT_FALSE(dir.path().empty());
  // 4096 nodes: fewer than the lattice's nominal spacing needs, so half of them differ.
  const std::string object =
      "    samples: 4\n    ambient_occlusion: {method: object, strength: 0.9, max_nodes: 4096}\n";
  render(config(dir.path(), "object", object));
  render(config(dir.path(), "object_tiny", object + "    budget_ms: 1.0e-6\n"));
  render(config(dir.path(), "object_cheapest", "    lod: {fraction: 0.02}\n"));
  if (world_rank() != 0) return;
  EXPECT_TRUE(image(dir.path(), "object", 0) == image(dir.path(), "object_tiny", 0));
  const auto cheapest = image(dir.path(), "object_cheapest", 1);
  ASSERT_FALSE(cheapest.empty());
  EXPECT_TRUE(cheapest == image(dir.path(), "object_tiny", 1));
  const std::vector<nlohmann::json> stats = budget_stats(dir.path(), "object_tiny");
  ASSERT_EQ(stats.size(), size_t(kSteps));
  EXPECT_EQ(stats[0]["ambient_occlusion"], "object");
  EXPECT_EQ(stats[0]["rungs"], 9) << stats[0];
  const nlohmann::json &b = stats[1];
  EXPECT_EQ(b["gives_up"], "lod 0.02") << b;
  EXPECT_EQ(b["ambient_occlusion"], "off");
  EXPECT_EQ(b["samples"], 1);
  EXPECT_EQ(b["unmet"], true);
}

}  // namespace
}  // namespace lantern::testing
