#include "core/pipeline/memory_budget.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>

#include "core/render/density_pass.h"

namespace lantern {
namespace {

constexpr int64_t kUnlimited = std::numeric_limits<int64_t>::max();
constexpr int64_t kPixelBytes = 8;  // RGBA8 + float depth

// The cgroup's memory limit (v2, else v1), or kUnlimited.
int64_t cgroup_limit() {
  for (const char *file :
       {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(file);
    std::string value;
    if (!(in >> value) || value == "max") continue;
    try {
      const long long limit = std::stoll(value);
      if (limit > 0) return limit;
    } catch (...) {
    }
  }
  return kUnlimited;
}

// What is left of a resource limit of this process, or kUnlimited.
int64_t rlimit_left(int resource, int64_t used) {
  rlimit limit{};
  if (getrlimit(resource, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return kUnlimited;
  return std::max<int64_t>(0, int64_t(limit.rlim_cur) - used);
}

// This process's virtual size (RLIMIT_AS counts it), from /proc; 0 where unknown.
int64_t virtual_size() {
  std::ifstream in("/proc/self/statm");
  int64_t pages = 0;
  if (!(in >> pages)) return 0;
  return pages * int64_t(sysconf(_SC_PAGESIZE));
}

}  // namespace

std::string byte_text(int64_t bytes) {
  const char *units[] = {"bytes", "kiB", "MiB", "GiB", "TiB", "PiB"};
  double value = double(bytes);
  int unit = 0;
  while (value >= 1024.0 && unit < 5) value /= 1024.0, ++unit;
  char text[48];
  if (unit == 0)
    std::snprintf(text, sizeof text, "%lld bytes", static_cast<long long>(bytes));
  else
    std::snprintf(text, sizeof text, "%.1f %s", value, units[unit]);
  return text;
}

std::vector<SceneMemory> estimate_scene_memory(const Config &config) {
  std::vector<SceneMemory> out;
  for (const SceneConfig &scene : config.scenes) {
    const int64_t pixels = int64_t(scene.width) * scene.height;
    const int64_t image = pixels * kPixelBytes;
    int64_t bytes = 0;
    if (scene.style == SceneStyle::kDensity) {
      bytes = 2 * pixels * density_channels(scene.color.by) * int64_t(sizeof(int64_t)) + image;
    } else {
      bytes = 2 * image * scene.samples + (scene.samples > 1 ? 2 * image : 0);
    }
    if (scene.output.asynchronous) bytes += image;
    out.push_back({scene.name, bytes});
  }
  return out;
}

MemoryShare node_memory_share(MPI_Comm comm) {
  MPI_Comm node = MPI_COMM_NULL;
  int node_ranks = 1;
  if (MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node) == MPI_SUCCESS) {
    MPI_Comm_size(node, &node_ranks);
    MPI_Comm_free(&node);
  }
  const int64_t physical = int64_t(sysconf(_SC_PHYS_PAGES)) * int64_t(sysconf(_SC_PAGESIZE));
  const int64_t cgroup = cgroup_limit();
  const bool by_cgroup = cgroup < physical;
  const int64_t node_bytes = by_cgroup ? cgroup : physical;
  MemoryShare share{node_bytes / std::max(1, node_ranks),
                    byte_text(node_bytes) + (by_cgroup ? " (the cgroup's limit)" : "") +
                        " on this node shared by " + std::to_string(node_ranks) + " rank" +
                        (node_ranks == 1 ? "" : "s")};
  const int64_t used = virtual_size();
  for (const auto &[resource, name] : {std::pair<int, const char *>{RLIMIT_AS, "RLIMIT_AS"},
                                       std::pair<int, const char *>{RLIMIT_DATA, "RLIMIT_DATA"}}) {
    const int64_t left = rlimit_left(resource, resource == RLIMIT_AS ? used : 0);
    if (left < share.bytes) share = {left, byte_text(left) + " left of this process's " + name};
  }
  return share;
}

Status check_scene_memory(const std::vector<SceneMemory> &scenes, const MemoryShare &share) {
  int64_t total = 0;
  for (const SceneMemory &s : scenes) total += s.bytes;
  if (total <= share.bytes) return {};
  std::vector<SceneMemory> largest = scenes;
  std::stable_sort(largest.begin(), largest.end(),
                   [](const SceneMemory &a, const SceneMemory &b) { return a.bytes > b.bytes; });
  std::string each;
  const size_t shown = std::min<size_t>(largest.size(), 8);
  for (size_t i = 0; i < shown; ++i)
    each += (i ? ", '" : "'") + largest[i].name + "' " + byte_text(largest[i].bytes);
  if (largest.size() > shown) each += ", and " + std::to_string(largest.size() - shown) + " more";
  return {StatusCode::kOutOfMemory,
          "scenes: the " + std::to_string(scenes.size()) + " scene" +
              (scenes.size() == 1 ? "" : "s") + " need about " + byte_text(total) +
              " per rank for their frames (" + each + "), more than the " + share.source +
              " allow" + (share.source.find("shared by") != std::string::npos ? "" : "s") + " (" +
              byte_text(share.bytes) +
              " per rank); lower width, height or samples, or render fewer scenes"};
}

}  // namespace lantern
