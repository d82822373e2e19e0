// One frame of particles read from a dump file: this rank's share, owned in memory, and a
// ParticleDescription view of it for lantern_publish(). Filled by the H5MD and LAMMPS readers.
#pragma once

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "core/dump/box.h"
#include "core/particles/particle_description.h"

namespace lantern {

struct ParticleFrame {
  int64_t step = 0;
  double time = 0.0;
  int64_t global_count = 0;       // particles of the frame over all ranks
  std::vector<double> position;   // x, y, z of each local particle
  std::vector<int64_t> type, id;  // empty when the file has none
  std::vector<double> scalar, radius;
  std::optional<Box> box;  // when the file records one

  int64_t count() const { return static_cast<int64_t>(position.size() / 3); }
  // Borrows this frame's vectors: valid while the frame is alive and unchanged.
  ParticleDescription view() const;
};

// The rows [begin, end) of n that `rank` of `size` reads: contiguous, sizes differ by <= 1.
std::pair<int64_t, int64_t> rank_share(int64_t n, int rank, int size);

// What a reader knows about a frame before reading it.
struct FrameInfo {
  int64_t step = 0;
  double time = 0.0;
  int64_t count = 0;  // particles of the frame (rows to split across ranks; for an H5MD file
                      // without Lantern's counts, the rows, fill rows included)
};

}  // namespace lantern
