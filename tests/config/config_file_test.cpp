// Reading configuration files: regular files only, capped by the bytes read. A FIFO blocked the
// reading rank forever; a link to /dev/zero grew memory without limit (its st_size is 0).
#include "core/config/config_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fcntl.h>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>

#include "core/config/config_loader.h"

namespace lantern {
namespace {

namespace fs = std::filesystem;

class ConfigFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("lantern_config_file_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// Runs `read` on another thread and gives up after a few seconds, so that a reader that blocks
// fails this test instead of hanging it (a writer then unblocks a FIFO's reader).
template <typename Read>
std::string within_seconds(const std::string &path, Read read) {
  auto reading = std::async(std::launch::async, read);
  if (reading.wait_for(std::chrono::seconds(5)) == std::future_status::ready) return reading.get();
  const int writer = ::open(path.c_str(), O_WRONLY | O_NONBLOCK);
  if (writer >= 0) ::close(writer);
  reading.wait();
  return "blocked for 5 s";
}

std::string read_within_seconds(const std::string &path, std::string *text) {
  return within_seconds(path, [&] { return read_config_file(path, text); });
}

TEST_F(ConfigFile, AFifoIsRefusedWithoutBlocking) {
  const std::string fifo = (dir_ / "config.fifo").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  std::string text;
  EXPECT_EQ(read_within_seconds(fifo, &text),
            "is a FIFO, not a regular file (a configuration is a YAML file)");
  // lantern_open's reader (every rank reads the file) too.
  const std::string loaded = within_seconds(fifo, [&] {
    Config config;
    const Status s = load_config(fifo, &config);
    return s.code == StatusCode::kConfig ? s.message : "status " + std::to_string(int(s.code));
  });
  EXPECT_EQ(loaded, "cannot read config file '" + fifo +
                        "': is a FIFO, not a regular file (a configuration is a YAML file)");
}

TEST_F(ConfigFile, LinksToEndlessDevicesAreRefused) {
  for (const char *device : {"/dev/zero", "/dev/urandom"}) {
    const fs::path link = dir_ / "device.yaml";
    fs::remove(link);
    fs::create_symlink(device, link);
    std::string text;
    EXPECT_EQ(read_within_seconds(link.string(), &text),
              "is a character device, not a regular file (a configuration is a YAML file)")
        << device;
    EXPECT_TRUE(text.empty());
  }
}

TEST_F(ConfigFile, TheCapCountsTheBytesRead) {
  const fs::path big = dir_ / "big.yaml";
  {
    std::ofstream out(big, std::ios::binary);
    const std::string line = "# " + std::string(1021, 'x') + "\n";
    for (int i = 0; i < 16 * 1024 + 1; ++i) out << line;
  }
  std::string text;
  EXPECT_EQ(read_config_file(big.string(), &text),
            "is larger than 16 MiB (a configuration is a YAML file)");
  fs::resize_file(big, kMaxConfigBytes);
  EXPECT_EQ(read_config_file(big.string(), &text), "");
  EXPECT_EQ(int64_t(text.size()), kMaxConfigBytes);
}

TEST_F(ConfigFile, DirectoriesMissingFilesAndEmptyFiles) {
  std::string text = "unchanged";
  EXPECT_EQ(read_config_file(dir_.string(), &text),
            "is a directory, not a regular file (a configuration is a YAML file)");
  EXPECT_EQ(read_config_file((dir_ / "missing.yaml").string(), &text), "No such file or directory");
  EXPECT_EQ(text, "unchanged");
  std::ofstream(dir_ / "empty.yaml").close();
  EXPECT_EQ(read_config_file((dir_ / "empty.yaml").string(), &text), "");
  EXPECT_EQ(text, "");
}

}  // namespace
}  // namespace lantern
