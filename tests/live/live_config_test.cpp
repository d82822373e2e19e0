// Live configuration under mpiexec (1-3 ranks): Runtime::reconfigure (lantern_reconfigure) and
// `watch: true`. Images are compared byte for byte; every rank checks what it switched to.
#include <gtest/gtest.h>
#include <mpi.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/pipeline/runtime.h"
#include "tests/dump/mpi_scratch_dir.h"
#include "tests/support/image_file.h"
#include "tests/support/mpi_world.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::read_bytes;
using testing::world_rank;
using testing::world_size;

// One run: a scratch directory shared by the ranks, this rank's share of a 14^3 lattice.
class LiveConfig : public ::testing::Test {
 protected:
  void SetUp() override {
    const int n = 14;
    for (int i = 0; i < n * n * n; ++i)
      if (i % world_size() == world_rank())
        x_.insert(x_.end(), {double(i % n), double((i / n) % n), double(i / (n * n))});
  }
  void TearDown() override {
    if (rt_) EXPECT_OK(rt_->finish());
    rt_.reset();
  }

  // A scene of the lattice drawn by the CPU raster; `scene_extra` adds lines to the scene.
  std::string config(const std::string &scene_extra, const std::string &top_extra = "") const {
    return "gl: none\nstats: '" + dir_.file("stats.jsonl") + "'\n" + top_extra +
           "scenes:\n  - name: s\n    width: 80\n    height: 60\n    renderer: cpu\n"
           "    camera: {azimuth: 35, elevation: 25}\n"
           "    output: {pattern: '" +
           dir_.file("s_{step:04d}.png") + "'}\n" + scene_extra;
  }
  std::string png(int step) const {
    char name[32];
    std::snprintf(name, sizeof name, "s_%04d.png", step);
    return dir_.file(name);
  }
  void open(const std::string &config_or_path) {
    ASSERT_OK(Runtime::open(config_or_path, MPI_COMM_WORLD, &rt_));
    ParticleDescription p{};
    p.count = int64_t(x_.size() / 3);
    p.position = {x_.data(), DataType::kFloat64, 0};
    ASSERT_OK(rt_->publish(p));
  }
  // Rank 0 writes `text` to `path` (atomically, as an editor saving would), then all ranks meet.
  static void write_file(const std::string &path, const std::string &text) {
    if (world_rank() == 0) {
      std::ofstream(path + ".tmp") << text;
      std::filesystem::rename(path + ".tmp", path);
    }
    MPI_Barrier(MPI_COMM_WORLD);
  }
  // The stats lines (rank 0 reads them; other ranks get an empty list).
  std::vector<std::string> stats_lines() const {
    std::vector<std::string> lines;
    std::ifstream in(dir_.file("stats.jsonl"));
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
  }
  static int count_of(const std::vector<std::string> &lines, const std::string &what) {
    int n = 0;
    for (const std::string &l : lines) n += l.find(what) != std::string::npos;
    return n;
  }

  MpiScratchDir dir_;
  std::vector<double> x_;
  std::unique_ptr<Runtime> rt_;
};

const std::string kCut = "    cut_planes: [{normal: [1, 0, 0], offset: 6.5}]\n";
// A plane that stays, and a second one added, removed or toggled next to it.
const std::string kOne = "    cut_planes: [{normal: [0, 0, 1], offset: 9.5}]\n";
const std::string kTwo =
    "    cut_planes: [{normal: [0, 0, 1], offset: 9.5}, {normal: [1, 0, 0], offset: 6.5}]\n";
const std::string kTwoOff =
    "    cut_planes: [{normal: [0, 0, 1], offset: 9.5},\n"
    "                 {normal: [1, 0, 0], offset: 6.5, enabled: false}]\n";

TEST_F(LiveConfig, ReconfigureChangesTheNextImageAndNothingEarlier) {
  open(config(""));
  ASSERT_OK(rt_->execute(0, 0.0));
  const std::vector<char> before = read_bytes(png(0));
  ASSERT_GT(before.size(), 100u);
  ASSERT_OK(rt_->reconfigure(config("    background: [0, 0, 0]\n")));
  EXPECT_EQ(rt_->configuration_changes(), 1);
  EXPECT_EQ(rt_->config().scenes.at(0).background[0], 0.0);
  EXPECT_EQ(read_bytes(png(0)), before);  // written images stay
  ASSERT_OK(rt_->execute(1, 0.0));
  EXPECT_NE(read_bytes(png(1)), before);
  ASSERT_OK(rt_->reconfigure(config("")));
  ASSERT_OK(rt_->execute(2, 0.0));
  EXPECT_EQ(read_bytes(png(2)), before);
}

TEST_F(LiveConfig, AddingThenRemovingACuttingPlaneGivesBackTheOriginalImage) {
  // The image of both planes drawn from scratch, by a context opened with them.
  open(config(kTwo));
  ASSERT_OK(rt_->execute(9, 0.0));
  const std::vector<char> two_from_scratch = read_bytes(png(9));
  ASSERT_OK(rt_->finish());

  open(config(kOne));
  ASSERT_OK(rt_->execute(0, 0.0));
  const std::vector<char> original = read_bytes(png(0));
  ASSERT_NE(original, two_from_scratch);
  ASSERT_OK(rt_->reconfigure(config(kTwo)));  // add
  ASSERT_OK(rt_->execute(0, 0.0));            // same step and particles: the bricks are cached
  EXPECT_EQ(read_bytes(png(0)), two_from_scratch);
  ASSERT_OK(rt_->reconfigure(config(kOne)));  // remove
  ASSERT_OK(rt_->execute(0, 0.0));
  EXPECT_EQ(read_bytes(png(0)), original);
  ASSERT_OK(rt_->reconfigure(config(kTwo)));  // add again, then toggle off and on
  ASSERT_OK(rt_->execute(0, 0.0));
  EXPECT_EQ(read_bytes(png(0)), two_from_scratch);
  ASSERT_OK(rt_->reconfigure(config(kTwoOff)));
  ASSERT_OK(rt_->execute(0, 0.0));
  EXPECT_EQ(read_bytes(png(0)), original);
  ASSERT_OK(rt_->reconfigure(config(kTwo)));
  ASSERT_OK(rt_->execute(0, 0.0));
  EXPECT_EQ(read_bytes(png(0)), two_from_scratch);
  ASSERT_OK(rt_->reconfigure(config("")));  // no plane at all: the scene as first drawn
  ASSERT_OK(rt_->execute(1, 0.0));
  ASSERT_OK(rt_->reconfigure(config(kOne)));  // new step: bricks refit, counts start over
  ASSERT_OK(rt_->execute(2, 0.0));
  EXPECT_EQ(read_bytes(png(2)), original);
}

TEST_F(LiveConfig, BadReconfigurationsKeepTheRunningConfiguration) {
  open(config(kCut));
  ASSERT_OK(rt_->execute(0, 0.0));
  const std::vector<char> before = read_bytes(png(0));
  struct Bad {
    std::string text;
    StatusCode code;
    std::string names;
  };
  const std::vector<Bad> bad = {
      {"scenes: [\n", StatusCode::kConfig, "malformed YAML"},
      {config("    backgrund: [0, 0, 0]\n"), StatusCode::kConfig, "backgrund"},
      {config("    width: -3\n"), StatusCode::kConfig, "width"},
      {"gl: auto\n" + config("").substr(std::string("gl: none\n").size()), StatusCode::kConfig,
       "gl: cannot change while running"},
      {config("", "watch: true\n"), StatusCode::kConfig, "watch: true needs"},
      {dir_.file("missing.yaml"), StatusCode::kConfig, "missing.yaml"}};
  for (const Bad &b : bad) {
    const Status s = rt_->reconfigure(b.text);
    EXPECT_EQ(s.code, b.code) << b.text;
    EXPECT_NE(s.message.find(b.names), std::string::npos) << s.message;
  }
  EXPECT_EQ(rt_->reconfigure(std::nullopt).code, StatusCode::kNullArgument);
  EXPECT_EQ(rt_->configuration_changes(), 0);
  ASSERT_OK(rt_->execute(1, 0.0));
  EXPECT_EQ(read_bytes(png(1)), before);
}

TEST_F(LiveConfig, RanksPassingDifferentConfigurationsFailOnEveryRank) {
  if (world_size() < 2) GTEST_SKIP() << "needs two ranks";
  open(config(""));
  ASSERT_OK(rt_->execute(0, 0.0));
  const std::vector<char> before = read_bytes(png(0));
  // The last rank alone asks for a black background.
  const bool odd_one = world_rank() == world_size() - 1;
  const Status s = rt_->reconfigure(config(odd_one ? "    background: [0, 0, 0]\n" : ""));
  EXPECT_EQ(s.code, StatusCode::kInvalidArgument);
  EXPECT_NE(s.message.find("rank " + std::to_string(world_size() - 1)), std::string::npos)
      << s.message;
  EXPECT_EQ(rt_->configuration_changes(), 0);
  ASSERT_OK(rt_->execute(1, 0.0));
  EXPECT_EQ(read_bytes(png(1)), before);
}

TEST_F(LiveConfig, RanksOpeningWithDifferentConfigurationsFailOnEveryRank) {
  if (world_size() < 2) GTEST_SKIP() << "needs two ranks";
  // Were it allowed, the last rank would watch a file the others do not look at.
  const bool odd_one = world_rank() == world_size() - 1;
  const Status s =
      Runtime::open(config(odd_one ? "    background: [0, 0, 0]\n" : ""), MPI_COMM_WORLD, &rt_);
  EXPECT_EQ(s.code, StatusCode::kInvalidArgument);
  EXPECT_NE(s.message.find("lantern_open"), std::string::npos) << s.message;
  EXPECT_EQ(rt_, nullptr);
}

// A host may call lantern_reconfigure with its unchanged file every step: that must neither parse
// nor rebuild anything. Asserted by what it does (every parse that succeeds replaces the
// configuration and is counted, as the equivalent text below shows), not by a clock: the time is
// printed for the reader, never compared on a shared machine.
TEST_F(LiveConfig, NoOpReconfigurationParsesNothing) {
  const std::string text = config(kCut);
  open(text);
  ASSERT_OK(rt_->execute(0, 0.0));
  const std::vector<char> before = read_bytes(png(0));
  const int reps = 200;
  std::vector<double> us;
  for (int i = 0; i < reps; ++i) {
    MPI_Barrier(MPI_COMM_WORLD);
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_OK(rt_->reconfigure(text));
    us.push_back(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
  }
  EXPECT_EQ(rt_->configuration_changes(), 0);  // nothing parsed, nothing replaced
  ASSERT_OK(rt_->execute(1, 0.0));
  EXPECT_EQ(read_bytes(png(1)), before);
  std::sort(us.begin(), us.end());
  // The same scene written differently parses, and keeps every buffer (no image changes).
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_OK(rt_->reconfigure(text + "\n# a comment\n"));
  const double reparse_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(rt_->configuration_changes(), 1);
  ASSERT_OK(rt_->execute(2, 0.0));
  EXPECT_EQ(read_bytes(png(2)), before);
  if (world_rank() == 0)
    std::printf(
        "[ live ] %d ranks: no-op lantern_reconfigure median %.1f us; an equivalent text "
        "(parsed, nothing rebuilt) %.1f us\n",
        world_size(), us[us.size() / 2], reparse_us);
}

TEST_F(LiveConfig, WatchedFileIsPickedUpAtTheNextScheduledStepOnEveryRank) {
  const std::string path = dir_.file("live.yaml");
  const std::string every2 = "watch: true\nschedule: {every: 2}\n";
  write_file(path, config("", every2));
  open(path);
  ASSERT_OK(rt_->execute(0, 0.0));
  const std::vector<char> original = read_bytes(png(0));

  write_file(path, config(kCut, every2));
  ASSERT_OK(rt_->execute(1, 0.0));  // not scheduled: not even looked at
  EXPECT_EQ(rt_->configuration_changes(), 0);
  ASSERT_OK(rt_->execute(2, 0.0));
  EXPECT_EQ(rt_->configuration_changes(), 1);  // on every rank
  ASSERT_EQ(rt_->config().scenes.at(0).cuts.size(), 1u);
  const std::vector<char> cut = read_bytes(png(2));
  EXPECT_NE(cut, original);

  // A bad edit: reported once, the last good configuration keeps drawing, the run goes on.
  write_file(path, config("    colour: {by: type}\n", every2));
  ASSERT_OK(rt_->execute(4, 0.0));
  ASSERT_OK(rt_->execute(6, 0.0));
  EXPECT_EQ(rt_->configuration_changes(), 1);
  EXPECT_EQ(read_bytes(png(4)), cut);
  EXPECT_EQ(read_bytes(png(6)), cut);
  // Deleted mid-run: reported once, configuration kept.
  if (world_rank() == 0) std::filesystem::remove(path);
  MPI_Barrier(MPI_COMM_WORLD);
  ASSERT_OK(rt_->execute(8, 0.0));
  ASSERT_OK(rt_->execute(10, 0.0));
  EXPECT_EQ(read_bytes(png(10)), cut);
  // The next good edit takes effect.
  write_file(path, config("", every2));
  ASSERT_OK(rt_->execute(12, 0.0));
  EXPECT_EQ(rt_->configuration_changes(), 2);
  EXPECT_EQ(read_bytes(png(12)), original);

  if (world_rank() == 0) {
    const std::vector<std::string> lines = stats_lines();
    ASSERT_EQ(lines.size(), 7u);
    EXPECT_EQ(count_of(lines, "\"config\""), 4);  // reload, bad edit, deletion, reload
    EXPECT_EQ(count_of(lines, "colour"), 1);
    EXPECT_EQ(count_of(lines, "No such file"), 1);
    EXPECT_EQ(count_of(lines, "reloaded"), 2);
  }
}

// The watched file replaced by something that is not a configuration: an empty file (an editor
// caught between truncating and writing), a FIFO (reading it blocked rank 0 forever), a link to
// /dev/zero (read without end). Each is reported once, by what it is, and the last good
// configuration keeps drawing; the next good edit applies.
TEST_F(LiveConfig, AWatchedFileThatIsNoLongerARegularFileIsReportedAndKept) {
  const std::string path = dir_.file("live.yaml");
  const std::string every2 = "watch: true\nschedule: {every: 2}\n";
  write_file(path, config("", every2));
  open(path);
  ASSERT_OK(rt_->execute(0, 0.0));
  const auto replace = [&](const std::function<void()> &make) {
    if (world_rank() == 0) {
      std::filesystem::remove(path);
      make();
    }
    MPI_Barrier(MPI_COMM_WORLD);
  };
  replace([&] { std::ofstream(path).close(); });
  ASSERT_OK(rt_->execute(2, 0.0));
  replace([&] { ASSERT_EQ(::mkfifo(path.c_str(), 0644), 0); });
  ASSERT_OK(rt_->execute(4, 0.0));
  replace([&] { std::filesystem::create_symlink("/dev/zero", path); });
  ASSERT_OK(rt_->execute(6, 0.0));
  EXPECT_EQ(rt_->configuration_changes(), 0);
  replace([&] { std::ofstream(path) << config(kCut, every2); });
  ASSERT_OK(rt_->execute(8, 0.0));
  EXPECT_EQ(rt_->configuration_changes(), 1);
  if (world_rank() == 0) {
    const std::vector<std::string> lines = stats_lines();
    ASSERT_EQ(lines.size(), 5u);
    EXPECT_NE(lines[1].find("live.yaml' is empty; keeping"), std::string::npos) << lines[1];
    EXPECT_NE(lines[2].find("live.yaml' is a FIFO, not a regular file"), std::string::npos)
        << lines[2];
    EXPECT_NE(lines[3].find("live.yaml' is a character device, not a regular file"),
              std::string::npos)
        << lines[3];
    EXPECT_NE(lines[4].find("reloaded"), std::string::npos) << lines[4];
  }
}

// stats: pointing at the configuration's own file would append JSON lines to it.
TEST_F(LiveConfig, StatsOrDumpAtTheConfigurationFileAreRefused) {
  const std::string path = dir_.file("self.yaml");
  const std::string scene =
      "scenes:\n  - name: s\n    width: 8\n    height: 8\n    output: {pattern: '" +
      dir_.file("self_{step}.png") + "'}\n";
  for (const std::string &top :
       {"stats: '" + path + "'\n", "stats: '" + dir_.file("./sub/../self.yaml") + "'\n",
        "dump: {file: '" + path + "'}\n"}) {
    write_file(path, "watch: true\n" + top + scene);
    const Status s = Runtime::open(path, MPI_COMM_WORLD, &rt_);
    EXPECT_EQ(s.code, StatusCode::kConfig) << top;
    EXPECT_NE(s.message.find("is the configuration file itself"), std::string::npos) << s.message;
    EXPECT_EQ(rt_, nullptr);
  }
  // On a reconfiguration too; the running configuration stays.
  write_file(path, scene);
  open(path);
  write_file(dir_.file("other.yaml"), "stats: '" + dir_.file("other.yaml") + "'\n" + scene);
  const Status s = rt_->reconfigure(dir_.file("other.yaml"));
  EXPECT_EQ(s.code, StatusCode::kConfig);
  EXPECT_NE(s.message.find("is the configuration file itself"), std::string::npos) << s.message;
}

// The stats lines and the dump in one file would break the dump's HDF5 (and the dump would replace
// the stats): refused at open and on a reconfiguration, through any spelling of the path.
TEST_F(LiveConfig, StatsAndDumpInOneFileAreRefused) {
  const std::string scene =
      "scenes:\n  - name: s\n    width: 8\n    height: 8\n    output: {pattern: '" +
      dir_.file("one_{step}.png") + "'}\n";
  const std::string both = "stats: '" + dir_.file("out.h5") + "'\ndump: {file: '" +
                           dir_.file("./sub/../out.h5") + "'}\n";
  write_file(dir_.file("both.yaml"), both + scene);
  Status s = Runtime::open(dir_.file("both.yaml"), MPI_COMM_WORLD, &rt_);
  EXPECT_EQ(s.code, StatusCode::kConfig);
  EXPECT_NE(s.message.find("dump.file: '" + dir_.file("./sub/../out.h5") + "' is also stats"),
            std::string::npos)
      << s.message;
  EXPECT_EQ(rt_, nullptr);
  write_file(dir_.file("apart.yaml"), scene);
  open(dir_.file("apart.yaml"));
  s = rt_->reconfigure(dir_.file("both.yaml"));
  EXPECT_EQ(s.code, StatusCode::kConfig);
  EXPECT_NE(s.message.find("is also stats"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace lantern
