#include "core/output/atomic_file.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace lantern
