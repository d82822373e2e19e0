// Object-space ambient occlusion over steps through the pipeline (three scenes, three volumes, one
// behind a cutting plane): from the second step on, each volume's deposit is taken from the
// bricks' refit's read of the positions (OcclusionVolume::arm_tap); every image must be the bytes a
// fresh run of that step alone writes (a deposit of its own) and the bytes rank 0 alone writes, at
// 1-4 ranks, and the stats line must say which deposit each step used: the refit's after a wobble,
// its own after a few particles jumped far (the grid grew past the refit's).
#include <gtest/gtest.h>

#include <mpi.h>

#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/pipeline/runtime.h"
#include "tests/support/image_file.h"
#include "tests/support/moving_lattice.h"
#include "tests/support/mpi_world.h"
#include "tests/support/one_step_render.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {
namespace {

// One thread: the refit hands its stream on only on one (a part per thread would not be in
// order).
std::string config(const std::string &dir, const std::string &run) {
  return "gl: none\nthreads: 1\nstats: " + dir + "/stats_" + run +
         ".jsonl\n"
         "scenes:\n"
         "  - name: ao\n    width: 320\n    height: 240\n    radius: 0.6\n"
         "    renderer: cpu\n    camera: {azimuth: 35, elevation: 25}\n"
         "    ambient_occlusion: {method: object, strength: 0.8}\n"
         "    output: {pattern: '" +
         dir + "/ao_" + run +
         "_{step}.png'}\n"
         "  - name: wide\n    width: 200\n    height: 200\n    radius: 0.5\n"
         "    renderer: cpu\n    camera: {azimuth: -60, elevation: 40}\n"
         "    ambient_occlusion: {method: object, radius: 3.5}\n"
         "    output: {pattern: '" +
         dir + "/wide_" + run +
         "_{step}.png'}\n"
         "  - name: cut\n    width: 240\n    height: 200\n    radius: 0.5\n"
         "    renderer: cpu\n    camera: {azimuth: 20, elevation: 30}\n"
         "    cut_planes: [{normal: [0.6, 0.8, 0], offset: 40.5}]\n"
         "    ambient_occlusion: {method: object, radius: 2.5}\n"
         "    output: {pattern: '" +
         dir + "/cut_" + run + "_{step}.png'}\n";
}

// On `comm` (MPI_COMM_SELF: rank 0 alone, the whole lattice).
void render(const std::string &yaml, const std::vector<int> &steps,
            MPI_Comm comm = MPI_COMM_WORLD) {
  std::unique_ptr<Runtime> rt;
  ASSERT_OK(Runtime::open(yaml, comm, &rt));
  for (const int step : steps) {
    const std::vector<double> xyz =
        comm == MPI_COMM_SELF ? moving_lattice(step, 0, 1) : moving_lattice(step);
    ParticleDescription p{};
    p.count = int64_t(xyz.size() / 3);
    p.position = {xyz.data(), DataType::kFloat64, 0};
    ASSERT_OK(rt->publish(p));
    ASSERT_OK(rt->execute(step, double(step)));
  }
  ASSERT_OK(rt->finish());
}

// The stats line of scene `scene`, step after step.
std::vector<nlohmann::json> scene_stats(const std::string &path, int scene) {
  std::vector<nlohmann::json> out;
  std::istringstream in(read_text(path));
  for (std::string line; std::getline(in, line);)
    out.push_back(nlohmann::json::parse(line)["scenes"][size_t(scene)]);
  return out;
}

// The stats lines' ao_deposit of scene `scene`, step after step.
std::vector<std::string> deposits(const std::string &path, int scene) {
  std::vector<std::string> out;
  std::istringstream in(read_text(path));
  for (std::string line; std::getline(in, line);)
    out.push_back(nlohmann::json::parse(line)["scenes"][size_t(scene)].value("ao_deposit", ""));
  return out;
}

TEST(ObjectAoSteps, TheRefitsDepositGivesTheImagesOfFreshRuns) {
  SharedScratchDir dir("/tmp/lantern_object_ao_steps_XXXXXX");
  ASSERT_FALSE(dir.path().empty());
  render(config(dir.path(), "steps"), {0, 1, 2});
  for (const int step : {0, 1, 2})
    render(config(dir.path(), "fresh" + std::to_string(step)), {step});
  if (world_rank() != 0) return;
  // The same steps on one rank alone: the same bytes whatever the rank count.
  render(config(dir.path(), "alone"), {0, 1, 2}, MPI_COMM_SELF);
  // Three scenes, three volumes (their own spacings): the refit hands its stream to all, the cut
  // scene's taking what its plane leaves.
  for (const char *run : {"steps", "alone"})
    for (const int scene : {0, 1, 2})
      EXPECT_EQ(deposits(dir.path() + "/stats_" + run + ".jsonl", scene),
                (std::vector<std::string>{"own", "refit", "own"}))
          << run << ", scene " << scene;
  // The volumes' nodes radius / 2 apart (4 x 0.6, 3.5 and 2.5: none capped), on every rank count.
  const double spacing[] = {1.2, 1.75, 1.25};
  for (const int scene : {0, 1, 2})
    for (const nlohmann::json &line : scene_stats(dir.path() + "/stats_steps.jsonl", scene)) {
      EXPECT_DOUBLE_EQ(line["ao_spacing"].get<double>(), spacing[scene]) << line;
      ASSERT_EQ(line["ao_nodes"].size(), 3u) << line;
      int64_t nodes = 1;
      for (const auto &n : line["ao_nodes"]) nodes *= n.get<int64_t>();
      EXPECT_GT(nodes, 8);
      EXPECT_LE(nodes, int64_t(1) << 18);
    }
  for (const int step : {0, 1, 2}) {
    const std::string s = std::to_string(step);
    for (const int scene : {0, 1, 2})
      EXPECT_EQ(deposits(dir.path() + "/stats_fresh" + s + ".jsonl", scene),
                std::vector<std::string>{"own"});
    for (const char *scene : {"ao", "wide", "cut"}) {
      const std::string name = dir.path() + "/" + scene;
      const auto steps = read_bytes(name + "_steps_" + s + ".png");
      const auto fresh = read_bytes(name + "_fresh" + s + "_" + s + ".png");
      ASSERT_FALSE(fresh.empty());
      EXPECT_TRUE(steps == fresh) << scene << ", step " << step;
      EXPECT_TRUE(steps == read_bytes(name + "_alone_" + s + ".png"))
          << scene << ", step " << step << ": " << world_size() << " ranks against one";
    }
  }
}

}  // namespace
}  // namespace lantern::testing
