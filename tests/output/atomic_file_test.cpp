#include "core/output/atomic_file.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <ctime>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "tests/output/scratch_dir.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

namespace fs = std::filesystem;

std::string read_all(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

bool contains(const std::string &s, const std::string &part) {
  return s.find(part) != std::string::npos;
}

TEST(AtomicFile, WritesAndCreatesDirectories) {
  const ScratchDir dir;
  const std::string path = dir.file("a/b/c/out.bin");
  const std::string data = "hello, lantern";
  ASSERT_OK(write_bytes_atomically(path, data.data(), data.size()));
  EXPECT_EQ(read_all(path), data);
  EXPECT_EQ(dir.entry_count(), 4u);  // a, a/b, a/b/c, out.bin: no temporary left
}

TEST(AtomicFile, ReplacesExistingFile) {
  const ScratchDir dir;
  const std::string path = dir.file("out.txt");
  ASSERT_OK(write_bytes_atomically(path, "old", 3));
  ASSERT_OK(write_bytes_atomically(path, "newer", 5));
  EXPECT_EQ(read_all(path), "newer");
  EXPECT_EQ(dir.entry_count(), 1u);
}

TEST(AtomicFile, TemporaryNameIsHiddenInSameDirectoryWithExtension) {
  const std::string temp = temporary_path_for("/x/y/frame_000001.png", ".png");
  EXPECT_EQ(fs::path(temp).parent_path(), fs::path("/x/y"));
  EXPECT_EQ(fs::path(temp).filename().string().front(), '.');
  EXPECT_EQ(fs::path(temp).extension(), ".png");
  EXPECT_NE(temp, temporary_path_for("/x/y/frame_000001.png", ".png"));  // unique per call
}

TEST(AtomicFile, FailedWriteLeavesOldFileAndNoTemporary) {
  const ScratchDir dir;
  const std::string path = dir.file("keep.txt");
  ASSERT_OK(write_bytes_atomically(path, "old", 3));
  std::string seen_temp;
  const Status status = write_atomically(path, ".txt", [&](const std::string &temp) {
    seen_temp = temp;
    std::ofstream(temp) << "partial";
    return Status(StatusCode::kIo, "disk on fire");
  });
  const std::string &error = status.message;
  EXPECT_EQ(status.code, StatusCode::kIo) << error;
  EXPECT_TRUE(contains(error, path)) << error;
  EXPECT_TRUE(contains(error, "disk on fire")) << error;
  EXPECT_FALSE(fs::exists(seen_temp));
  EXPECT_EQ(read_all(path), "old");
  EXPECT_EQ(dir.entry_count(), 1u);
}

TEST(AtomicFile, ThrowingWriterIsReportedAndCleanedUp) {
  const ScratchDir dir;
  const std::string path = dir.file("new.txt");
  const Status status = write_atomically(
      path, ".txt", [](const std::string &) -> Status { throw std::runtime_error("boom"); });
  const std::string &error = status.message;
  EXPECT_EQ(status.code, StatusCode::kIo) << error;
  EXPECT_TRUE(contains(error, "boom")) << error;
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(dir.entry_count(), 0u);
}

TEST(AtomicFile, UnwritableDirectoryNamesPathAndReason) {
  const std::string path = "/proc/lantern_x/a.png";
  const Status status = write_bytes_atomically(path, "x", 1);
  const std::string &error = status.message;
  EXPECT_EQ(status.code, StatusCode::kIo) << error;
  EXPECT_TRUE(contains(error, "/proc/lantern_x")) << error;
  EXPECT_FALSE(fs::exists(path));
}

TEST(AtomicFile, PathUnderRegularFileNamesPathAndReason) {
  const ScratchDir dir;
  const std::string blocker = dir.file("plain_file");
  ASSERT_OK(write_bytes_atomically(blocker, "x", 1));
  const std::string path = blocker + "/sub/a.png";
  const Status status = write_bytes_atomically(path, "x", 1);
  const std::string &error = status.message;
  EXPECT_EQ(status.code, StatusCode::kIo) << error;
  EXPECT_TRUE(contains(error, blocker)) << error;
  EXPECT_TRUE(contains(error, "Not a directory")) << error;
  EXPECT_EQ(dir.entry_count(), 1u);
}

// Age a file: its modification time an hour ago.
void make_old(const std::string &path) {
  const timespec times[2] = {{::time(nullptr) - 3600, 0}, {::time(nullptr) - 3600, 0}};
  ::utimensat(AT_FDCWD, path.c_str(), times, 0);
}

TEST(AtomicFile, StaleTemporariesOfAKilledRunAreRemovedAndNothingElse) {
  const ScratchDir dir;
  const auto make = [&](const std::string &name, bool old) {
    std::ofstream(dir.file(name)) << "x";
    if (old) make_old(dir.file(name));
    return dir.file(name);
  };
  // A process id no process has (above the kernel's pid_max of 2^22).
  const std::string dead = "99999999";
  const std::string live = std::to_string(::getpid());
  const std::string stale = make(".img_000001.png.tmp" + dead + "-3.png", true);
  const std::string stale_bare = make(".stats.tmp" + dead + "-0", true);
  const std::string fresh = make(".img_000002.png.tmp" + dead + "-4.png", false);
  const std::string running = make(".img_000003.png.tmp" + live + "-5.png", true);
  const std::string other_hidden = make(".img.tmp-notours.png", true);
  const std::string image = make("img_000001.png", true);
  const std::string notes = make(".notes", true);
  const std::vector<std::string> removed =
      remove_stale_temporaries(dir.path().string(), ::time(nullptr) - 60);
  EXPECT_EQ(removed.size(), 2u);
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_FALSE(fs::exists(stale_bare));
  for (const std::string &kept : {fresh, running, other_hidden, image, notes})
    EXPECT_TRUE(fs::exists(kept)) << kept;
  // A missing folder is nothing to clean.
  EXPECT_TRUE(remove_stale_temporaries(dir.file("missing"), ::time(nullptr)).empty());
}

}  // namespace
}  // namespace lantern
