// Test support: render one step of a configuration through the pipeline (core/pipeline/runtime.h)
// on every rank of MPI_COMM_WORLD and read back what it wrote. For tests that check pixels of a
// small scene end to end: the scratch directory, the run and the stats line, in one place.
#pragma once

#include <gtest/gtest.h>

#include <mpi.h>

#include <unistd.h>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>

#include "core/pipeline/runtime.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {

// A fresh directory made by rank 0 from `pattern` (mkdtemp's, ending in XXXXXX) and named the same
// on every rank, so that every rank reads one configuration text. Removed with what it holds when
// the object goes; empty (and tests fail on their files) if it could not be made.
class SharedScratchDir {
 public:
  explicit SharedScratchDir(const char *pattern) {
    char dir[128] = {};
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank == 0 && std::string(pattern).size() < sizeof dir) {
      std::string(pattern).copy(dir, sizeof dir - 1);
      if (!mkdtemp(dir)) dir[0] = '\0';
    }
    MPI_Bcast(dir, sizeof dir, MPI_CHAR, 0, MPI_COMM_WORLD);
    path_ = dir;
    owner_ = rank == 0;
  }
  ~SharedScratchDir() {
    if (owner_ && !path_.empty()) std::system(("rm -rf '" + path_ + "'").c_str());
  }
  SharedScratchDir(const SharedScratchDir &) = delete;
  SharedScratchDir &operator=(const SharedScratchDir &) = delete;

  const std::string &path() const { return path_; }

 private:
  std::string path_;
  bool owner_ = false;
};

// Opens a runtime on `yaml`, publishes `particles`, executes step 0 and finishes, expecting every
// call to succeed (collective: every rank calls it).
inline void render_one_step(const std::string &yaml, const ParticleDescription &particles) {
  std::unique_ptr<Runtime> rt;
  EXPECT_OK(Runtime::open(yaml, MPI_COMM_WORLD, &rt));
  if (!rt) return;
  EXPECT_OK(rt->publish(particles));
  EXPECT_OK(rt->execute(0, 0.0));
  EXPECT_OK(rt->finish());
}

// The whole text of a file ("" when it cannot be read).
inline std::string read_text(const std::string &path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace lantern::testing
