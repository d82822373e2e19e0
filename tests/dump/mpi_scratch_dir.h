// A fresh directory shared by every rank of MPI_COMM_WORLD for one test, removed afterwards.
// Rank 0 picks the name (its pid) and broadcasts it; construction and destruction are collective.
#pragma once

#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace lantern {

class MpiScratchDir {
 public:
  MpiScratchDir() {
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    std::string path;
    if (rank == 0) {
      const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
      // '/' in a parameterised suite's or test's name would make a tree whose parents stay
      // behind: one directory instead.
      std::string name = "lantern_dump_" + std::string(info->test_suite_name()) + "_" +
                         info->name() + "_" + std::to_string(::getpid());
      std::replace(name.begin(), name.end(), '/', '_');
      path = (std::filesystem::path(::testing::TempDir()) / name).string();
      std::filesystem::remove_all(path);
      std::filesystem::create_directories(path);
    }
    int length = static_cast<int>(path.size());
    MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD);
    path.resize(static_cast<size_t>(length));
    MPI_Bcast(path.data(), length, MPI_CHAR, 0, MPI_COMM_WORLD);
    path_ = path;
  }
  ~MpiScratchDir() {
    MPI_Barrier(MPI_COMM_WORLD);
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    std::error_code ignored;
    if (rank == 0) std::filesystem::remove_all(path_, ignored);
  }
  MpiScratchDir(const MpiScratchDir &) = delete;
  MpiScratchDir &operator=(const MpiScratchDir &) = delete;

  std::string file(const std::string &name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace lantern
