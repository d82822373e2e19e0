// A dump failure on one rank of several: one rank's HDF5 step fails (an
// injected fault: as root, permissions cannot make one rank's view unwritable), and every rank
// must return the same error naming the file instead of waiting in a collective call that the
// failing rank skipped. CTest runs this at 3 ranks with a timeout, so a hang fails the test.
#include <gtest/gtest.h>
#include <mpi.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/common/injected_fault.h"
#include "core/dump/h5md_reader.h"
#include "h5md_series_frames.h"
#include "lantern/lantern.h"
#include "mpi_scratch_dir.h"
#include "tests/support/mpi_world.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::world_rank;
using testing::world_size;

constexpr int kFaultyRank = 1;

struct ContextCloser {
  void operator()(lantern_context *c) const { lantern_close(c); }
};
using Context = std::unique_ptr<lantern_context, ContextCloser>;

// 40 + 7 * rank particles per rank on a line; ids are global.
struct Particles {
  std::vector<double> xyz;
  std::vector<int64_t> id;
  explicit Particles(int64_t step) {
    int64_t first = 0;
    for (int r = 0; r < world_rank(); ++r) first += 40 + 7 * r;
    for (int64_t i = 0; i < 40 + 7 * world_rank(); ++i) {
      const int64_t g = first + i;
      xyz.insert(xyz.end(), {0.5 * g + 0.01 * step, 0.25 * (g % 5), 0.0});
      id.push_back(g);
    }
  }
  lantern_particles view() const {
    lantern_particles p{};
    p.count = static_cast<int64_t>(id.size());
    p.position = {xyz.data(), LANTERN_FLOAT64, 0};
    p.id = {id.data(), LANTERN_INT64, 0};
    return p;
  }
};

// A folder shared by every rank for one test (removed afterwards), and the dump file open_run
// writes in it.
struct RunFolder {
  MpiScratchDir scratch;
  std::string dir = std::filesystem::path(scratch.file("run.h5")).parent_path().string();
  std::string file = dir + "/run.h5";
};

Context open_run(const std::string &dir) {
  const std::string yaml =
      "scenes:\n"
      "  - name: f\n"
      "    width: 48\n"
      "    height: 32\n"
      "    radius: 0.3\n"
      "    renderer: cpu\n"
      "    output: {pattern: '" +
      dir + "/f_{step:06d}.png'}\n" + "dump:\n  file: " + dir + "/run.h5\n";
  lantern_context *raw = nullptr;
  const lantern_status st = lantern_open(yaml.c_str(), MPI_Comm_c2f(MPI_COMM_WORLD), &raw);
  Context ctx(raw);
  EXPECT_EQ(st, LANTERN_OK) << lantern_error_message(ctx.get());
  return ctx;
}

lantern_status step(lantern_context *ctx, int64_t s) {
  const Particles p(s);
  const lantern_particles v = p.view();
  EXPECT_EQ(lantern_publish(ctx, &v), LANTERN_OK);
  return lantern_execute(ctx, s, double(s));
}

// Rank 0's text on every rank, to compare each rank's message with.
std::string rank0_text(std::string text) {
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD);
  text.resize(static_cast<size_t>(length));
  MPI_Bcast(text.data(), length, MPI_CHAR, 0, MPI_COMM_WORLD);
  return text;
}

bool image_exists(const std::string &dir, int64_t s) {
  char name[32];
  std::snprintf(name, sizeof(name), "/f_%06lld.png", static_cast<long long>(s));
  return std::filesystem::exists(dir + name);
}

// The fault points: local work before a collective call, the collective calls of a frame (the
// value and step datasets, the box, the count), and the flush.
class DumpFault : public ::testing::TestWithParam<const char *> {};

TEST_P(DumpFault, OneRankFailingAFrameStopsTheDumpOnEveryRankAndRenderingGoesOn) {
  ASSERT_GE(world_size(), 2) << "run under mpiexec -n 3";
  const RunFolder run;
  const std::string &dir = run.dir, &file = run.file;
  {
    const Context ctx = open_run(dir);
    ASSERT_EQ(step(ctx.get(), 0), LANTERN_OK) << lantern_error_message(ctx.get());
    if (world_rank() == kFaultyRank) inject_fault(GetParam());
    EXPECT_EQ(step(ctx.get(), 1), LANTERN_ERR_IO);
    const std::string message = lantern_error_message(ctx.get());
    EXPECT_EQ(message, rank0_text(message)) << "every rank reports the same error";
    EXPECT_NE(message.find("dump.file: " + file + ": step 1: "), std::string::npos) << message;
    EXPECT_NE(message.find(GetParam()), std::string::npos) << message;
    EXPECT_NE(message.find("dump stopped for the rest of the run; " + file +
                           " keeps its 1 earlier frame"),
              std::string::npos)
        << message;
    MPI_Barrier(MPI_COMM_WORLD);
    EXPECT_TRUE(image_exists(dir, 1)) << "the failed dump does not stop rendering";
    // The next step works on every rank: the image is written, the dump stays off.
    EXPECT_EQ(step(ctx.get(), 2), LANTERN_OK) << lantern_error_message(ctx.get());
    MPI_Barrier(MPI_COMM_WORLD);
    EXPECT_TRUE(image_exists(dir, 2));
  }
  inject_fault("");
  // The file was closed consistently and keeps frame 0, readable as a whole; the failed frame
  // was cut back, even where only its final flush failed (its step returned an error).
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  ASSERT_EQ(reader->frames().size(), 1u);
  // Every time series was rolled back to the complete frames: no value one frame longer than its
  // step (a frame of zeros that a reader taking value's length would read).
  if (world_rank() == 0)
    EXPECT_EQ(testing::time_series_mismatch(file, reader->frames().size()), "");
  EXPECT_EQ(reader->frames()[0].step, 0);
  int64_t mine = 40 + 7 * world_rank(), total = 0;
  MPI_Allreduce(&mine, &total, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(reader->frames()[0].count, total);
  ParticleFrame frame;
  ASSERT_OK(reader->read(0, 0, total, &frame));
  ASSERT_EQ(frame.count(), total);
  for (int64_t i = 0; i < total; ++i) EXPECT_EQ(frame.position[3 * i], 0.5 * frame.id[i]);
}

INSTANTIATE_TEST_SUITE_P(Points, DumpFault,
                         ::testing::Values("gather the frame", "position/value: select",
                                           "position/value: write", "id/value: extend",
                                           "id/step: write", "edges/value: write",
                                           "particle_count/value: write", "flush after frame 2"));

// A failure while creating the file on one rank: before the file exists (the rank cannot write
// the directory) or after (its metadata, groups or first flush: the half-built file is removed,
// where it made every later dump fail as "exists"). Every rank gets the same error, the image is
// still written, no file is left, and the next scheduled dump creates the file.
struct CreateFault {
  const char *fault, *reported;  // the injected step; what the message says about it
};
class DumpFaultOnCreate : public ::testing::TestWithParam<CreateFault> {};

TEST_P(DumpFaultOnCreate, OneRankFailingTheCreateIsAgreedAndTheNextDumpRetries) {
  ASSERT_GE(world_size(), 2) << "run under mpiexec -n 3";
  const RunFolder run;
  const std::string &dir = run.dir, &file = run.file;
  {
    const Context ctx = open_run(dir);
    if (world_rank() == kFaultyRank) inject_fault(GetParam().fault);
    EXPECT_EQ(step(ctx.get(), 0), LANTERN_ERR_IO);
    const std::string message = lantern_error_message(ctx.get());
    EXPECT_EQ(message, rank0_text(message));
    EXPECT_NE(message.find("dump.file: " + file + ": step 0: "), std::string::npos) << message;
    EXPECT_NE(message.find(GetParam().reported), std::string::npos) << message;
    EXPECT_FALSE(std::filesystem::exists(file));
    EXPECT_TRUE(image_exists(dir, 0)) << "the image is still written";
    EXPECT_EQ(step(ctx.get(), 1), LANTERN_OK) << lantern_error_message(ctx.get());
    EXPECT_EQ(step(ctx.get(), 2), LANTERN_OK) << lantern_error_message(ctx.get());
  }
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  ASSERT_EQ(reader->frames().size(), 2u);
  EXPECT_EQ(reader->frames()[0].step, 1);
}

INSTANTIATE_TEST_SUITE_P(Steps, DumpFaultOnCreate,
                         ::testing::Values(CreateFault{"file is writable", "file is writable"},
                                           CreateFault{"metadata", "metadata (injected fault)"}));

// A file that one rank cannot see (a node-local disk, a relative path in another working
// directory): opening it for reading fails on every rank with that rank's reason, where the
// others used to wait for ever in HDF5's collective open. The faulty rank asks for a name that
// does not exist; the others for the real file.
TEST(DumpFaultOnRead, AFileMissingOnOneRankFailsTheOpenOnEveryRank) {
  ASSERT_GE(world_size(), 2) << "run under mpiexec -n 3";
  const RunFolder run;
  const std::string &dir = run.dir, &file = run.file;
  {
    const Context ctx = open_run(dir);
    ASSERT_EQ(step(ctx.get(), 0), LANTERN_OK) << lantern_error_message(ctx.get());
  }
  const std::string missing = dir + "/not_here.h5";
  std::unique_ptr<H5mdReader> reader;
  const Status s =
      H5mdReader::open(world_rank() == kFaultyRank ? missing : file, MPI_COMM_WORLD, &reader);
  EXPECT_EQ(s.code, StatusCode::kIo);
  EXPECT_NE(s.message.find("not_here.h5: cannot open the file"), std::string::npos) << s.message;
  EXPECT_EQ(s.message, rank0_text(s.message)) << "every rank reports the same error";
  EXPECT_EQ(reader, nullptr);
  // Nothing is left in flight: the file opens on every rank afterwards.
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  EXPECT_EQ(reader->frames().size(), 1u);
}

}  // namespace
}  // namespace lantern
