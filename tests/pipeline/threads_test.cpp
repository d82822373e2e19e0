// `threads: N`: brick building and refitting, the particle scan and the CPU raster's column strips
// run on N threads, and so do the screen-space cues' rows and object AO's deposit; every image byte
// and every count of the stats line must be the one-thread result, over steps that build the
// bricks, refit them (particles moved a little) and repair them (a few particles jumped far), at 1
// and 2 ranks - with bonds too, whose half-bonds each strip draws and culls against its own depth.
#include <gtest/gtest.h>

#include <mpi.h>

#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/config/config_loader.h"
#include "core/pipeline/runtime.h"
#include "tests/support/image_file.h"
#include "tests/support/moving_lattice.h"
#include "tests/support/mpi_world.h"
#include "tests/support/one_step_render.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {
namespace {

std::string config(const std::string &dir, const std::string &threads) {
  return "gl: none\nthreads: " + threads + "\nstats: " + dir + "/stats_" + threads +
         ".jsonl\n"
         "scenes:\n"
         "  - name: hzb\n    width: 640\n    height: 480\n    radius: 0.6\n"
         "    renderer: cpu\n    culling: {occlusion: hzb}\n"
         "    camera: {azimuth: 35, elevation: 25}\n"
         "    output: {pattern: '" +
         dir + "/hzb_" + threads +
         "_{step}.png'}\n"
         "  - name: ssaa\n    width: 520\n    height: 300\n    radius: 0.5\n    samples: 4\n"
         "    renderer: cpu\n    culling: {occlusion: none}\n"
         "    cut_planes: [{normal: [1, 1, 0], offset: 70.0}]\n"
         "    output: {pattern: '" +
         dir + "/ssaa_" + threads +
         "_{step}.png'}\n"
         "  - name: bonds\n    width: 640\n    height: 480\n    radius: 0.3\n"
         "    renderer: cpu\n    culling: {occlusion: hzb}\n"
         "    camera: {azimuth: 35, elevation: 25}\n    bonds: {radius: 0.12}\n"
         "    output: {pattern: '" +
         dir + "/bonds_" + threads +
         "_{step}.png'}\n"
         "  - name: cues\n    width: 640\n    height: 480\n    radius: 0.6\n"
         "    renderer: cpu\n    camera: {azimuth: 35, elevation: 25}\n"
         "    ambient_occlusion: {method: screen}\n    outline: {}\n    depth_cue: {}\n"
         "    output: {pattern: '" +
         dir + "/cues_" + threads +
         "_{step}.png'}\n"
         "  - name: ao_full\n    width: 240\n    height: 180\n    radius: 0.6\n"
         "    renderer: cpu\n    camera: {azimuth: 35, elevation: 25}\n"
         "    ambient_occlusion: {method: screen, resolution: full}\n"
         "    output: {pattern: '" +
         dir + "/ao_full_" + threads +
         "_{step}.png'}\n"
         "  - name: oao\n    width: 480\n    height: 360\n    radius: 0.6\n"
         "    renderer: cpu\n    camera: {azimuth: 35, elevation: 25}\n"
         "    ambient_occlusion: {method: object}\n"
         "    output: {pattern: '" +
         dir + "/oao_" + threads + "_{step}.png'}\n";
}

// Bonds along x between neighbours of one row of this rank's slab (local indices, pairs).
std::vector<int64_t> row_bonds(int64_t count) {
  const int64_t n = 64;
  std::vector<int64_t> pairs;
  for (int64_t i = 0; i + 1 < count; ++i)
    if (i % n != n - 1) pairs.insert(pairs.end(), {i, i + 1});
  return pairs;
}

TEST(Threads, ImagesAndCountsAreTheOneThreadBytes) {
  SharedScratchDir dir("/tmp/lantern_threads_XXXXXX");
  ASSERT_FALSE(dir.path().empty());
  const std::vector<std::string> counts = {"1", "2", "3", "4"};
  for (const std::string &threads : counts) {
    std::unique_ptr<Runtime> rt;
    ASSERT_OK(Runtime::open(config(dir.path(), threads), MPI_COMM_WORLD, &rt));
    for (int step = 0; step < 3; ++step) {
      const std::vector<double> xyz = moving_lattice(step);
      ParticleDescription p{};
      p.count = int64_t(xyz.size() / 3);
      p.position = {xyz.data(), DataType::kFloat64, 0};
      ASSERT_OK(rt->publish(p));
      const std::vector<int64_t> pairs = row_bonds(p.count);
      BondDescription b;
      b.count = int64_t(pairs.size() / 2);
      b.first = {pairs.data(), DataType::kInt64, 16};
      b.second = {pairs.data() + 1, DataType::kInt64, 16};
      ASSERT_OK(rt->publish_bonds(b));
      ASSERT_OK(rt->execute(step, double(step)));
    }
    ASSERT_OK(rt->finish());
  }
  if (world_rank() != 0) return;
  for (const std::string &threads : counts)
    for (const char *scene : {"hzb", "ssaa", "bonds", "cues", "ao_full", "oao"})
      for (int step = 0; step < 3; ++step) {
        const auto one =
            read_bytes(dir.path() + "/" + scene + "_1_" + std::to_string(step) + ".png");
        const auto many = read_bytes(dir.path() + "/" + scene + "_" + threads + "_" +
                                     std::to_string(step) + ".png");
        ASSERT_FALSE(one.empty());
        EXPECT_TRUE(one == many) << scene << " step " << step << " threads " << threads;
      }
  // The counts of every step, and what the bricks did (built, refit, refit with repairs).
  const auto lines = [&](const std::string &threads) {
    std::vector<nlohmann::json> out;
    std::istringstream in(read_text(dir.path() + "/stats_" + threads + ".jsonl"));
    for (std::string line; std::getline(in, line);) {
      nlohmann::json j = nlohmann::json::parse(line);
      // Timings, and the compositing schedule, which a measured cost model picks, vary by run.
      for (auto &s : j["scenes"])
        for (const char *key : {"ms", "per_rank", "file", "composite", "composite_method"})
          s.erase(key);
      out.push_back({j["particles"], j["scenes"]});
    }
    return out;
  };
  const std::vector<nlohmann::json> one = lines("1");
  ASSERT_EQ(one.size(), 3u);
  EXPECT_EQ(one[0][1][0]["bricks"], "built");
  EXPECT_EQ(one[1][1][0]["bricks"], "refit");
  EXPECT_EQ(one[2][1][0]["bricks"], "refit");
  ASSERT_TRUE(one[0][1][2].contains("bonds"));
  // Object AO's deposit shares the refit's read of the positions, on every thread count (the
  // comparison below): its own deposit on the first step, the refit's after.
  EXPECT_EQ(one[0][1][5]["ao_deposit"], "own");
  EXPECT_EQ(one[1][1][5]["ao_deposit"], "refit");
  EXPECT_GT(one[0][1][2]["bonds"]["drawn"].get<int64_t>(), 0);
  for (const std::string &threads : counts) EXPECT_EQ(lines(threads), one) << threads;
}

TEST(Threads, KeyTakesAutoOrACount) {
  Config c;
  EXPECT_OK(load_config("threads: auto\nscenes: [{name: a}]\n", &c));
  EXPECT_EQ(c.threads, 0);
  EXPECT_OK(load_config("threads: 6\nscenes: [{name: a}]\n", &c));
  EXPECT_EQ(c.threads, 6);
  const Status zero = load_config("threads: 0\nscenes: [{name: a}]\n", &c);
  EXPECT_EQ(zero.code, StatusCode::kConfig);
  EXPECT_NE(zero.message.find("threads"), std::string::npos) << zero.message;
  EXPECT_EQ(load_config("threads: many\nscenes: [{name: a}]\n", &c).code, StatusCode::kConfig);
}

}  // namespace
}  // namespace lantern::testing
