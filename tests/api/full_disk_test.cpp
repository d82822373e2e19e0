// A full disk under a running simulation: the step returns LANTERN_ERR_IO, the process goes on,
// and every file stays valid - no image at its name, no hidden temporary file, the stats file
// whole JSON lines, every H5MD time series as long as its step.
//
// Two ways to fill the disk. RLIMIT_FSIZE (tests/support/file_size_limit.h) runs anywhere: every
// file of the process may grow only so far, which gives the short and failed writes of ENOSPC to
// the image writers and the stats file. A real ENOSPC, on a 2 MiB tmpfs filled to the last byte,
// covers everything at once, the HDF5 dump included (HDF5 extends its file with ftruncate, which
// RLIMIT_FSIZE refuses where a full disk allows it); it needs the right to mount (root here) and
// is skipped where mount(2) is refused.
#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/api/api_fixture.h"
#include "tests/dump/h5md_series_frames.h"
#include "tests/support/file_size_limit.h"

namespace lantern::testing {
namespace {

namespace fs = std::filesystem;

using FullDiskApi = ApiTest;

// The steps of the stats file; fails the test on a line that is not JSON.
std::vector<int64_t> stats_steps(const fs::path &path) {
  std::ifstream in(path);
  std::vector<int64_t> steps;
  for (std::string line; std::getline(in, line);) {
    const nlohmann::json record = nlohmann::json::parse(line, nullptr, false);
    EXPECT_FALSE(record.is_discarded()) << "not a JSON line: " << line;
    if (!record.is_discarded()) steps.push_back(record["step"].get<int64_t>());
  }
  return steps;
}

void expect_no_temporary_files(const fs::path &dir) {
  for (const auto &entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos)
        << "temporary file left: " << entry.path();
}

std::string scene(const std::string &name, const fs::path &dir, const char *extension) {
  return "  - name: " + name +
         "\n"
         "    width: 160\n"
         "    height: 120\n"
         "    renderer: cpu\n"
         "    output: {pattern: '" +
         (dir / (name + "_{step:04d}.")).string() + extension + "'}\n";
}

TEST_F(FullDiskApi, JpegAndStatsFailTheStepAndStayValid) {
  ASSERT_EQ(
      open("stats: '" + (dir_ / "stats.jsonl").string() + "'\nscenes:\n" + scene("j", dir_, "jpg")),
      LANTERN_OK)
      << message();
  std::vector<double> x = lattice(8);
  const lantern_particles p = interleaved(x);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  lantern_status full = LANTERN_OK;
  {
    // Room for 20 more bytes in any file: the image and the stats line fail.
    const FileSizeLimit limit(int64_t(fs::file_size(dir_ / "stats.jsonl")) + 20);
    full = lantern_execute(ctx_, 1, 0.1);
  }
  EXPECT_EQ(full, LANTERN_ERR_IO) << message();
  EXPECT_NE(message().find("j_0001.jpg"), std::string::npos) << message();
  EXPECT_FALSE(fs::exists(dir_ / "j_0001.jpg"));
  // Room again: the next step renders and its stats line starts on a line of its own.
  EXPECT_EQ(lantern_execute(ctx_, 2, 0.2), LANTERN_OK) << message();
  EXPECT_TRUE(fs::exists(dir_ / "j_0002.jpg"));
  EXPECT_EQ(stats_steps(dir_ / "stats.jsonl"), (std::vector<int64_t>{0, 2}));
  expect_no_temporary_files(dir_);
}

// A tmpfs mounted for the test (unmounted, lazily, by the destructor). A mount left at the same
// place by a run that died is detached first.
class Tmpfs {
 public:
  explicit Tmpfs(const fs::path &at) : at_(at) {
    ::umount2(at.c_str(), MNT_DETACH);
    fs::create_directories(at);
    if (::mount("lantern-test", at.c_str(), "tmpfs", MS_NOSUID | MS_NODEV, "size=2m") != 0)
      error_ = std::strerror(errno);
  }
  ~Tmpfs() {
    if (error_.empty()) ::umount2(at_.c_str(), MNT_DETACH);
    std::error_code ignored;
    fs::remove(at_, ignored);  // the mount point, empty again: nothing left in the temp dir
  }
  const std::string &error() const { return error_; }

 private:
  fs::path at_;
  std::string error_;
};

// Fills the file system of `dir` to the last byte; the file is removed by remove().
void fill(const fs::path &file) {
  std::ofstream out(file, std::ios::binary);
  const std::string block(4096, 'x');
  while (out.write(block.data(), block.size())) {
  }
  out.close();
  std::ofstream tail(file, std::ios::binary | std::ios::app);  // the last partial block
  while (tail.put('x')) tail.flush();
}

TEST_F(FullDiskApi, OnAFullTmpfsEveryWriterFailsTheStepAndStaysValid) {
  const fs::path disk = fs::temp_directory_path() / "lantern_api_full_tmpfs";
  const Tmpfs tmpfs(disk);
  if (!tmpfs.error().empty()) GTEST_SKIP() << "cannot mount a tmpfs here: " << tmpfs.error();
  const std::string config = "stats: '" + (disk / "stats.jsonl").string() + "'\nscenes:\n" +
                             scene("p", disk, "png") + scene("j", disk, "jpg") +
                             scene("t", disk, "tif") + scene("e", disk, "exr") +
                             "dump:\n  file: '" + (disk / "run.h5").string() + "'\n";
  ASSERT_EQ(open(config), LANTERN_OK) << message();
  std::vector<double> x = lattice(8);
  const lantern_particles p = interleaved(x);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  fill(disk / "filler");
  EXPECT_EQ(lantern_execute(ctx_, 1, 0.1), LANTERN_ERR_IO) << message();
  fs::remove(disk / "filler");
  for (const char *name : {"p_0001.png", "j_0001.jpg", "t_0001.tif", "e_0001.exr"})
    EXPECT_FALSE(fs::exists(disk / name)) << name;
  EXPECT_EQ(lantern_execute(ctx_, 2, 0.2), LANTERN_OK) << message();
  for (const char *name : {"p_0002.png", "j_0002.jpg", "t_0002.tif", "e_0002.exr"})
    EXPECT_TRUE(fs::exists(disk / name)) << name;
  ASSERT_EQ(lantern_close(ctx_), LANTERN_OK);
  ctx_ = nullptr;
  EXPECT_EQ(stats_steps(disk / "stats.jsonl"), (std::vector<int64_t>{0, 2}));
  // The dump stopped at the failed frame and keeps frame 0, every time series cut back to it.
  EXPECT_EQ(time_series_mismatch((disk / "run.h5").string(), 1), "");
  expect_no_temporary_files(disk);
}

}  // namespace
}  // namespace lantern::testing
