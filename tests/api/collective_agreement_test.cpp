// Collective calls of the C API when the ranks' arguments differ or are bad: every rank must
// return the same status and none may wait forever for a collective call that another rank
// skipped (CTest runs this at 2 and 3 ranks with a timeout, so a hang fails the test), and a bad
// communicator is an error status, never an abort of the whole job.
#include <gtest/gtest.h>
#include <mpi.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/common/injected_fault.h"
#include "lantern/lantern.h"
#include "tests/support/mpi_world.h"
#include "tests/support/shared_test_dir.h"

namespace lantern::testing {
namespace {

namespace fs = std::filesystem;

struct ContextCloser {
  void operator()(lantern_context *c) const { lantern_close(c); }
};
using Context = std::unique_ptr<lantern_context, ContextCloser>;

std::string config_for(const fs::path &dir) {
  return "scenes:\n  - name: s\n    width: 32\n    height: 24\n    renderer: cpu\n"
         "    output: {pattern: '" +
         (dir / "s_{step:04d}.png").string() + "'}\n";
}

// A context opened with `config` on every rank, three particles (kept alive in a static: the
// context borrows them) published on each; null, with a failure recorded, where either fails.
Context open_with_three_particles(const std::string &config) {
  static const std::vector<double> x = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  lantern_context *raw = nullptr;
  const lantern_status opened = lantern_open(config.c_str(), LANTERN_COMM_WORLD, &raw);
  Context ctx(raw);
  EXPECT_EQ(opened, LANTERN_OK) << lantern_error_message(raw);
  if (opened != LANTERN_OK) return Context();
  lantern_particles p{};
  p.count = 3;
  p.position = {x.data(), LANTERN_FLOAT64, 0};
  EXPECT_EQ(lantern_publish(raw, &p), LANTERN_OK) << lantern_error_message(raw);
  return ctx;
}

// Every rank's status, gathered: all equal to `expected`.
void expect_on_every_rank(lantern_status status, lantern_status expected) {
  std::vector<int> all(static_cast<size_t>(world_size()), 0);
  const int mine = int(status);
  MPI_Allgather(&mine, 1, MPI_INT, all.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (size_t r = 0; r < all.size(); ++r) EXPECT_EQ(all[r], int(expected)) << "rank " << r;
}

TEST(BadCommunicator, AGarbageHandleIsAnErrorNamingItNotAnAbort) {
  for (const int handle : {100, 123456, -7}) {
    lantern_context *raw = nullptr;
    const lantern_status st = lantern_open("scenes: [{}]\n", handle, &raw);
    const Context ctx(raw);
    EXPECT_EQ(st, LANTERN_ERR_MPI);
    EXPECT_NE(std::string(lantern_error_message(raw)).find("mpi_comm_f: " + std::to_string(handle)),
              std::string::npos)
        << lantern_error_message(raw);
  }
  // MPI still works for the host afterwards, with its own error handler.
  MPI_Errhandler handler = MPI_ERRHANDLER_NULL;
  MPI_Comm_get_errhandler(MPI_COMM_WORLD, &handler);
  EXPECT_EQ(handler, MPI_ERRORS_ARE_FATAL);
  MPI_Errhandler_free(&handler);
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(BadCommunicator, AnIntercommunicatorIsRefusedOnEveryRank) {
  ASSERT_GE(world_size(), 2) << "run under mpiexec -n 2 or more";
  const int half = world_rank() % 2;
  MPI_Comm local = MPI_COMM_NULL, inter = MPI_COMM_NULL;
  MPI_Comm_split(MPI_COMM_WORLD, half, world_rank(), &local);
  MPI_Intercomm_create(local, 0, MPI_COMM_WORLD, half == 0 ? 1 : 0, 17, &inter);
  lantern_context *raw = nullptr;
  const lantern_status st = lantern_open("scenes: [{}]\n", MPI_Comm_c2f(inter), &raw);
  const Context ctx(raw);
  EXPECT_EQ(st, LANTERN_ERR_MPI);
  EXPECT_NE(std::string(lantern_error_message(raw)).find("intercommunicator"), std::string::npos)
      << lantern_error_message(raw);
  MPI_Comm_free(&inter);
  MPI_Comm_free(&local);
}

TEST(OpenAgreement, ANullConfigOnOneRankFailsTheOpenOnEveryRank) {
  ASSERT_GE(world_size(), 2) << "run under mpiexec -n 2 or more";
  const SharedDir dir;
  const std::string config = config_for(dir.path());
  lantern_context *raw = nullptr;
  const lantern_status st =
      lantern_open(world_rank() == 1 ? nullptr : config.c_str(), LANTERN_COMM_WORLD, &raw);
  const Context ctx(raw);
  expect_on_every_rank(st, LANTERN_ERR_NULL_ARGUMENT);
  EXPECT_NE(std::string(lantern_error_message(raw)).find("config: NULL"), std::string::npos)
      << lantern_error_message(raw);
  // A NULL `out` on one rank, likewise.
  lantern_context *other = nullptr;
  const lantern_status st2 =
      lantern_open(config.c_str(), LANTERN_COMM_WORLD, world_rank() == 1 ? nullptr : &other);
  lantern_close(other);
  expect_on_every_rank(st2, LANTERN_ERR_NULL_ARGUMENT);
}

TEST(ReconfigureAgreement, TheSameTextAsAPathOnRankZeroAndInlineElsewhere) {
  const SharedDir dir;
  const std::string config = config_for(dir.path());
  const fs::path file = dir.path() / "same.yaml";
  if (world_rank() == 0) std::ofstream(file) << config;
  MPI_Barrier(MPI_COMM_WORLD);
  const Context ctx = open_with_three_particles(config);
  lantern_context *const raw = ctx.get();
  ASSERT_NE(raw, nullptr);
  // Rank 0 names the file, the others pass its text: rank 0's "nothing changed" differs from
  // theirs, and the decision must be agreed before anyone enters a collective call.
  const std::string path = file.string();
  for (int round = 0; round < 2; ++round) {
    const lantern_status st =
        lantern_reconfigure(raw, world_rank() == 0 ? path.c_str() : config.c_str());
    expect_on_every_rank(st, LANTERN_OK);
    expect_on_every_rank(lantern_execute(raw, round, 0.0), LANTERN_OK);
  }
  if (world_rank() == 0) EXPECT_TRUE(fs::exists(dir.path() / "s_0001.png"));
}

// Rank 0 draws the overlays alone, then broadcasts the outcome: memory running out there threw
// past the broadcast, and the other ranks waited in it for ever. Now every rank returns
// LANTERN_ERR_OUT_OF_MEMORY, and the next step draws its overlays again.
TEST(RankZeroWork, MemoryRunningOutInTheOverlaysFailsTheStepOnEveryRank) {
  const SharedDir dir;
  const std::string config = config_for(dir.path()) + "    box: {}\n";
  const Context ctx = open_with_three_particles(config);
  lantern_context *const raw = ctx.get();
  ASSERT_NE(raw, nullptr);
  if (world_rank() == 0) inject_fault("overlays: draw");
  const lantern_status failed = lantern_execute(raw, 0, 0.0);
  inject_fault("");
  expect_on_every_rank(failed, LANTERN_ERR_OUT_OF_MEMORY);
  EXPECT_NE(std::string(lantern_error_message(raw)).find("overlays: out of memory"),
            std::string::npos)
      << lantern_error_message(raw);
  expect_on_every_rank(lantern_execute(raw, 1, 0.0), LANTERN_OK);
  if (world_rank() == 0) EXPECT_TRUE(fs::exists(dir.path() / "s_0001.png"));
}

}  // namespace
}  // namespace lantern::testing
