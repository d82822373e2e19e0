// The memory a configuration's scenes ask of every rank, checked when the configuration is
// opened or replaced (lantern_open, lantern_reconfigure, a watched file), so that a configuration
// that cannot fit is refused with its figures instead of failing an allocation mid-run, or
// getting the rank killed by the kernel's out-of-memory killer.
//
// The estimate counts the large per-scene buffers a rank holds at once, per scene (bytes):
//   spheres: the drawn frame at sample resolution, P S 8 (RGBA8 + float depth; P = width x
//            height, S = samples), twice (compositing exchanges up to a frame's worth); with
//            S > 1 also the final image, P 8, twice (its band and the gathered image); with
//            output.asynchronous one more final frame (the image in flight).
//   density: the summed footprints, P C 8 (int64; C = 1 channel for color.by solid, else 4),
//            twice (this rank's sums and the reduction), and the final frame, P 8.
// The particles and bricks are the simulation's and grow with it; they are not counted.
//
// What a rank may use: the node's memory (or its cgroup's limit, when lower) shared by the ranks
// of the communicator on that node, and the process's RLIMIT_AS / RLIMIT_DATA (what is left of
// them), whichever is least.
// Thread-safety: pure functions, except node_memory_share (collective).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/config/config.h"

namespace lantern {

struct SceneMemory {
  std::string name;
  int64_t bytes = 0;
};

// The estimate above, per scene, in the configuration's order.
std::vector<SceneMemory> estimate_scene_memory(const Config &config);

// What this rank may use, in bytes, and how that was found (for messages): e.g. "24.0 GiB on
// this node shared by 4 ranks". Collective over comm (it counts the ranks on each node).
struct MemoryShare {
  int64_t bytes = 0;
  std::string source;
};
MemoryShare node_memory_share(MPI_Comm comm);

// OK when the scenes' sum fits `share`; else kOutOfMemory naming the total, the figure of each
// scene (the largest first, at most eight) and what the rank may use.
Status check_scene_memory(const std::vector<SceneMemory> &scenes, const MemoryShare &share);

// "1.5 GiB", "640.0 MiB", "12.0 kiB" (binary units, one decimal).
std::string byte_text(int64_t bytes);

}  // namespace lantern
