// A fresh, empty directory per test, removed afterwards (RAII).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace lantern {

class ScratchDir {
 public:
  ScratchDir() {
    const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
    // A parameterised suite's and test's names hold '/' ("Formats/ImageWriter", "Round/3"): one
    // directory, not a tree whose parents would stay behind in the temporary directory.
    std::string name = "lantern_" + std::string(info->test_suite_name()) + "_" + info->name() +
                       "_" + std::to_string(::getpid());
    std::replace(name.begin(), name.end(), '/', '_');
    path_ = std::filesystem::path(::testing::TempDir()) / name;
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir &) = delete;
  ScratchDir &operator=(const ScratchDir &) = delete;

  std::string file(const std::string &name) const { return (path_ / name).string(); }
  const std::filesystem::path &path() const { return path_; }

  // Number of entries (recursively), to prove no temporary file was left behind.
  size_t entry_count() const {
    size_t n = 0;
    for (auto it = std::filesystem::recursive_directory_iterator(path_);
         it != std::filesystem::recursive_directory_iterator(); ++it)
      ++n;
    return n;
  }

 private:
  std::filesystem::path path_;
};

}  // namespace lantern
