// Per-rank statistics (the nine-spheres paper's Fig. 5) in the stats line and lantern_load_summary,
// through the C API under mpiexec at 2 and 3 ranks: every rank publishes a different load, so the
// spread, the imbalance and the rank of the max are known exactly, and the per-rank means times the
// rank count must give the line's totals. Compositing's bytes and messages per rank balance over
// the ranks.
#include <gtest/gtest.h>

#include <mpi.h>

#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lantern/lantern.h"
#include "tests/dump/mpi_scratch_dir.h"
#include "tests/support/mpi_world.h"

namespace lantern::testing {
namespace {

nlohmann::json last_line(const std::string &path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return nlohmann::json::parse(last);
}

TEST(PerRankStats, SpreadsSumToTheTotalsAndNameTheBusiestRank) {
  const MpiScratchDir dir;
  const int rank = world_rank(), size = world_size();
  // Rank r draws 200 (r + 1) particles and loses 50 (size - r) beyond the cutting plane z = 5.5:
  // the last rank draws most, rank 0 culls most.
  const int drawn = 200 * (rank + 1), culled = 50 * (size - rank);
  std::vector<double> xyz;
  for (int i = 0; i < drawn + culled; ++i) {
    const double z = i < drawn ? 5.0 * (i % 7) / 7.0 : 6.0 + (i % 3);
    xyz.insert(xyz.end(), {double(i % 13), double((i / 13) % 11) + 0.3 * rank, z});
  }
  const std::string config = "gl: none\nstats: " + dir.file("stats.jsonl") +
                             "\nscenes:\n  - name: a\n    width: 64\n    height: 48\n"
                             "    radius: 0.3\n    culling: {occlusion: none}\n"
                             "    cut_planes: [{normal: [0, 0, 1], offset: 5.5}]\n"
                             "    output: {pattern: '" +
                             dir.file("a_{step}.png") + "'}\n";
  lantern_context *ctx = nullptr;
  ASSERT_EQ(lantern_open(config.c_str(), LANTERN_COMM_WORLD, &ctx), LANTERN_OK)
      << lantern_error_message(ctx);
  lantern_particles p{};
  p.count = drawn + culled;
  p.position = lantern_array{xyz.data(), LANTERN_FLOAT64, 0};
  ASSERT_EQ(lantern_publish(ctx, &p), LANTERN_OK) << lantern_error_message(ctx);
  EXPECT_STREQ(lantern_load_summary(ctx), "");  // nothing rendered yet
  ASSERT_EQ(lantern_execute(ctx, 3, 0.0), LANTERN_OK) << lantern_error_message(ctx);
  const std::string summary = lantern_load_summary(ctx);
  ASSERT_EQ(lantern_close(ctx), LANTERN_OK);
  if (rank != 0) {
    EXPECT_EQ(summary, "");
    return;
  }
  EXPECT_NE(summary.find("step 3, " + std::to_string(size) + " ranks"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("scene 'a' per rank: drawn 200.." + std::to_string(200 * size)),
            std::string::npos)
      << summary;

  const nlohmann::json scene = last_line(dir.file("stats.jsonl"))["scenes"][0];
  const nlohmann::json &per_rank = scene["per_rank"];
  const double n = size;
  // drawn: 200, 400, ... -> min 200, max 200 size on the last rank, mean 100 (size + 1).
  EXPECT_EQ(per_rank["drawn"]["min"], 200.0);
  EXPECT_EQ(per_rank["drawn"]["max"], 200.0 * n);
  EXPECT_EQ(per_rank["drawn"]["max_rank"], size - 1);
  EXPECT_DOUBLE_EQ(per_rank["drawn"]["imbalance"].get<double>(), 2.0 * n / (n + 1.0));
  // culled: 50 size, ..., 50 -> the max on rank 0.
  EXPECT_EQ(per_rank["culled"]["min"], 50.0);
  EXPECT_EQ(per_rank["culled"]["max"], 50.0 * n);
  EXPECT_EQ(per_rank["culled"]["max_rank"], 0);
  // The per-rank spreads add up to the line's totals.
  for (const char *what : {"drawn", "culled"}) {
    EXPECT_DOUBLE_EQ(per_rank[what]["mean"].get<double>() * n,
                     scene["particles"][what].get<double>())
        << what;
  }
  // particles: each rank's finite particles, drawn + culled: 200 (r + 1) + 50 (size - r), the
  // most on the last rank.
  EXPECT_EQ(per_rank["particles"]["min"], 200.0 + 50.0 * n);
  EXPECT_EQ(per_rank["particles"]["max"], 200.0 * n + 50.0);
  EXPECT_EQ(per_rank["particles"]["max_rank"], size - 1);
  EXPECT_NE(summary.find(", particles "), std::string::npos) << summary;
  EXPECT_EQ(scene["particles"]["drawn"], 100 * size * (size + 1));
  EXPECT_EQ(scene["particles"]["culled"], 25 * size * (size + 1));
  for (const char *what : {"drawn", "culled", "ms", "particles"}) {
    const nlohmann::json &s = per_rank[what];
    EXPECT_GE(s["imbalance"].get<double>(), 1.0) << what;
    EXPECT_GE(s["max_rank"].get<int>(), 0) << what;
    EXPECT_LT(s["max_rank"].get<int>(), size) << what;
    EXPECT_LE(s["min"].get<double>(), s["mean"].get<double>()) << what;
    EXPECT_LE(s["mean"].get<double>(), s["max"].get<double>()) << what;
  }
  EXPECT_GT(per_rank["ms"]["max"].get<double>(), 0.0);

  // Compositing's traffic per rank: every byte and message one rank sent another received, no
  // rank sends more than its whole 64 x 48 frame at 8 bytes a pixel (plus run-length headers),
  // and the schedule and the measured cost model it was chosen by are named.
  const nlohmann::json &composite = scene["composite"];
  ASSERT_TRUE(composite.is_object()) << scene.dump();
  EXPECT_FALSE(composite["schedule"].get<std::string>().empty());
  EXPECT_TRUE(composite["cost_model"]["measured"].get<bool>());
  EXPECT_GT(composite["cost_model"]["latency_us"].get<double>(), 0.0);
  EXPECT_GT(composite["cost_model"]["gb_per_s"].get<double>(), 0.0);
  for (const char *cpu : {"scan_ns", "encode_ns", "merge_ns", "dense_merge_ns"})
    EXPECT_GT(composite["cost_model"][cpu].get<double>(), 0.0) << cpu;
  EXPECT_DOUBLE_EQ(composite["bytes_sent"]["mean"].get<double>(),
                   composite["bytes_received"]["mean"].get<double>());
  EXPECT_DOUBLE_EQ(composite["messages_sent"]["mean"].get<double>(),
                   composite["messages_received"]["mean"].get<double>());
  EXPECT_GT(composite["bytes_sent"]["max"].get<double>(), 0.0);
  EXPECT_GE(composite["messages_sent"]["max"].get<double>(), 1.0);
  EXPECT_LE(composite["bytes_sent"]["max"].get<double>(), 8.0 * 64 * 48 + 1024);
  // The cost model measures this machine, so either schedule may win. Sending active pixels:
  // every rank drew something, and no more than the frame. The dense schedule scans no frame
  // whole, so it counts no active pixel.
  if (composite["schedule"].get<std::string>().rfind("dense ", 0) == 0) {
    EXPECT_EQ(composite["active_pixels"]["max"].get<double>(), 0.0);
  } else {
    EXPECT_GT(composite["active_pixels"]["min"].get<double>(), 0.0);
    EXPECT_LE(composite["active_pixels"]["max"].get<double>(), 64.0 * 48);
  }
}

}  // namespace
}  // namespace lantern::testing
