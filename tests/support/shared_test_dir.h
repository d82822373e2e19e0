// Test support: a scratch directory every rank of MPI_COMM_WORLD shares (named after the test and
// rank 0's pid), created before and removed after the test's collective calls.
#pragma once

#include <gtest/gtest.h>
#include <mpi.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

#include "tests/support/mpi_world.h"

namespace lantern::testing {

class SharedDir {
 public:
  // `prefix` starts the directory's name under the system's temporary directory.
  explicit SharedDir(const std::string &prefix = "lantern_shared_") {
    long id = world_rank() == 0 ? long(::getpid()) : 0;
    MPI_Bcast(&id, 1, MPI_LONG, 0, MPI_COMM_WORLD);
    const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            (prefix + std::string(info->name()) + "_" + std::to_string(id));
    if (world_rank() == 0) std::filesystem::create_directories(path_);
    MPI_Barrier(MPI_COMM_WORLD);
  }
  ~SharedDir() {
    MPI_Barrier(MPI_COMM_WORLD);
    std::error_code ignored;
    if (world_rank() == 0) std::filesystem::remove_all(path_, ignored);
  }
  SharedDir(const SharedDir &) = delete;
  SharedDir &operator=(const SharedDir &) = delete;
  const std::filesystem::path &path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace lantern::testing
