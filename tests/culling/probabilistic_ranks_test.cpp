// occlusion: probabilistic on several MPI ranks through the C API: a rerun of the same step at
// the same rank count and split writes the same bytes (each rank's random numbers are keyed by
// step, pixel, sample and iteration; its decisions use its own particles only), and every rank
// finishes the step (no rank waits in a collective another skipped). Run at 1, 2 and 3 ranks.
#include <gtest/gtest.h>

#include <mpi.h>

#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "lantern/lantern.h"
#include "tests/support/image_file.h"
#include "tests/support/mpi_world.h"

namespace lantern::testing {
namespace {

// A scratch directory made by rank 0 and known to every rank.
std::string shared_directory() {
  char path[256] = "/tmp/lantern_probabilistic_ranks_XXXXXX";
  if (world_rank() == 0 && mkdtemp(path) == nullptr) path[0] = '\0';
  MPI_Bcast(path, sizeof path, MPI_CHAR, 0, MPI_COMM_WORLD);
  return path;
}

TEST(ProbabilisticRanks, RerunsAtTheSameRankCountWriteTheSameBytes) {
  const std::string dir = shared_directory();
  ASSERT_FALSE(dir.empty());
  const int rank = world_rank(), ranks = world_size();
  // A 36^3 block of particles, round robin over the ranks (every rank sees the whole block).
  std::vector<double> x;
  for (int i = 0; i < 36 * 36 * 36; ++i)
    if (i % ranks == rank)
      x.insert(x.end(), {double(i % 36), double(i / 36 % 36), double(i / 1296)});
  lantern_particles p{};
  p.count = int64_t(x.size() / 3);
  p.position = {x.data(), LANTERN_FLOAT64, 0};
  for (const char *run : {"a", "b"}) {
    const std::string config =
        "scenes:\n  - width: 128\n    height: 96\n    radius: 0.6\n"
        "    culling: {occlusion: probabilistic, confidence: 0.9}\n"
        "    output: {pattern: '" +
        dir + "/" + run + "_{step:04d}.png'}\n";
    lantern_context *ctx = nullptr;
    ASSERT_EQ(lantern_open(config.c_str(), LANTERN_COMM_WORLD, &ctx), LANTERN_OK);
    ASSERT_EQ(lantern_publish(ctx, &p), LANTERN_OK) << lantern_error_message(ctx);
    EXPECT_EQ(lantern_execute(ctx, 5, 0.0), LANTERN_OK) << lantern_error_message(ctx);
    EXPECT_EQ(lantern_close(ctx), LANTERN_OK);
  }
  if (rank == 0) {
    const auto a = read_bytes(dir + "/a_0005.png"), b = read_bytes(dir + "/b_0005.png");
    EXPECT_GT(a.size(), 1000u);
    EXPECT_EQ(a, b) << ranks << " ranks";
    std::system(("rm -rf '" + dir + "'").c_str());
  }
}

}  // namespace
}  // namespace lantern::testing
