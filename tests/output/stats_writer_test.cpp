#include "core/output/stats_writer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/output/scratch_dir.h"
#include "tests/support/file_size_limit.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

std::vector<std::string> lines_of(const std::string &path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(StatsWriter, AppendsOneParsableLinePerCall) {
  const ScratchDir dir;
  const std::string path = dir.file("run/stats.jsonl");
  {
    StatsWriter writer(path);
    ASSERT_OK(writer.append({{"step", 0}, {"render_ms", 1.5}}));
    ASSERT_OK(writer.append({{"step", 10}, {"render_ms", 2.0}, {"scene", "top"}}));
    // Flushed per call: visible to a reader before the writer closes.
    EXPECT_EQ(lines_of(path).size(), 2u);
  }
  const std::vector<std::string> lines = lines_of(path);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(nlohmann::json::parse(lines[0])["step"], 0);
  EXPECT_EQ(nlohmann::json::parse(lines[1])["scene"], "top");
}

TEST(StatsWriter, ReopeningAppendsInsteadOfTruncating) {
  const ScratchDir dir;
  const std::string path = dir.file("stats.jsonl");
  ASSERT_OK(append_json_line(path, {{"step", 1}}));
  ASSERT_OK(append_json_line(path, {{"step", 2}}));
  EXPECT_EQ(lines_of(path).size(), 2u);
}

TEST(StatsWriter, InvalidUtf8IsReplacedNotThrown) {
  const ScratchDir dir;
  const std::string path = dir.file("stats.jsonl");
  EXPECT_OK(append_json_line(path, {{"name", std::string("bad\xff")}}));
  EXPECT_EQ(lines_of(path).size(), 1u);
}

TEST(StatsWriter, UnwritablePathIsNamed) {
  StatsWriter writer("/proc/lantern_x/stats.jsonl");
  const Status status = writer.append({{"step", 0}});
  const std::string &error = status.message;
  EXPECT_EQ(status.code, StatusCode::kIo) << error;
  EXPECT_NE(error.find("/proc/lantern_x"), std::string::npos) << error;
}

// A full disk in the middle of a line (the file may grow by 10 more bytes): the line is written
// whole or not at all, so the file stays valid JSON lines and the next line starts on its own.
TEST(StatsWriter, AFailedAppendLeavesNoPartialLine) {
  const ScratchDir dir;
  const std::string path = dir.file("stats.jsonl");
  StatsWriter writer(path);
  ASSERT_OK(writer.append({{"step", 0}}));
  const auto before = std::filesystem::file_size(path);
  Status failed;
  {
    const testing::FileSizeLimit full(int64_t(before) + 10);
    failed = writer.append({{"step", 1}, {"scene", std::string(200, 'x')}});
  }
  EXPECT_EQ(failed.code, StatusCode::kIo);
  EXPECT_NE(failed.message.find(path), std::string::npos) << failed.message;
  EXPECT_EQ(std::filesystem::file_size(path), before) << "a partial line stayed in the file";
  ASSERT_OK(writer.append({{"step", 2}}));
  ASSERT_OK(append_json_line(path, {{"step", 3}}));
  const std::vector<std::string> lines = lines_of(path);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(nlohmann::json::parse(lines[0])["step"], 0);
  EXPECT_EQ(nlohmann::json::parse(lines[1])["step"], 2);
  EXPECT_EQ(nlohmann::json::parse(lines[2])["step"], 3);
}

// A run killed while writing a line leaves its start in the file; the next open cuts it off, so
// the new line does not continue it (it did: two records broken into one unparsable line).
TEST(StatsWriter, AnIncompleteLastLineIsCutBeforeTheNextLine) {
  const ScratchDir dir;
  const std::string path = dir.file("stats.jsonl");
  ASSERT_OK(append_json_line(path, {{"step", 0}}));
  ASSERT_OK(append_json_line(path, {{"step", 1}}));
  std::ofstream(path, std::ios::app) << "{\"step\": 2, \"scene";  // killed here
  ASSERT_OK(append_json_line(path, {{"step", 3}}));
  std::vector<std::string> lines = lines_of(path);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(nlohmann::json::parse(lines[1])["step"], 1);
  EXPECT_EQ(nlohmann::json::parse(lines[2])["step"], 3);
  // A file holding only the start of its first line, and one of a long line (beyond a block).
  std::ofstream(path, std::ios::trunc) << "{\"step\": 4";
  ASSERT_OK(append_json_line(path, {{"step", 5}}));
  lines = lines_of(path);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(nlohmann::json::parse(lines[0])["step"], 5);
  std::ofstream(path, std::ios::app) << "{\"scene\": \"" << std::string(10000, 'x');
  StatsWriter writer(path);
  ASSERT_OK(writer.append({{"step", 6}}));
  ASSERT_OK(writer.append({{"step", 7}}));
  EXPECT_OK(writer.close());
  lines = lines_of(path);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(nlohmann::json::parse(lines[1])["step"], 6);
  EXPECT_EQ(nlohmann::json::parse(lines[2])["step"], 7);
}

}  // namespace
}  // namespace lantern
