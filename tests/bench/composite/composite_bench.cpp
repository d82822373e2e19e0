// lantern-bench-composite: times composite_frames for each method and image size on the ranks it
// is launched with (tests/bench/composite.sh runs it at 1, 2, 4 and 8 ranks and builds the table).
//
// Each timing is root's wall time inside composite_frames after a barrier (when the merged image
// is ready on root), including scratch allocation, packing and unpacking; the median of --reps
// runs after --warmup runs is printed. Output, from rank 0, one line per (size, method):
//   ranks=<p> size=<w>x<h> method=<name> ran=<method that ran> median_ms=<m> min_ms=<m> runs=<n>
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "core/composite/depth_compositor.h"
#include "core/view/frame.h"

namespace {

struct Options {
  std::vector<std::pair<int, int>> sizes{{1024, 1024}, {1920, 1080}, {4096, 4096}, {6144, 3072}};
  std::vector<std::string> methods{"reduce64", "reduce_scatter", "binary_swap", "direct_send",
                                   "auto"};
  int reps = 7;
  int warmup = 2;
  size_t chunk = 0;
};

std::vector<std::string> split(const std::string &text, char sep) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, sep);)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

bool parse_options(int argc, char **argv, Options *o) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&](const char *name) -> const char * {
      const std::string prefix = std::string(name) + "=";
      return arg.rfind(prefix, 0) == 0 ? argv[i] + prefix.size() : nullptr;
    };
    if (const char *v = value("--sizes")) {
      o->sizes.clear();
      for (const std::string &s : split(v, ',')) {
        int w = 0, h = 0;
        if (std::sscanf(s.c_str(), "%dx%d", &w, &h) != 2 || w <= 0 || h <= 0) return false;
        o->sizes.emplace_back(w, h);
      }
    } else if (const char *v = value("--methods")) {
      o->methods = split(v, ',');
    } else if (const char *v = value("--reps")) {
      o->reps = std::max(1, std::atoi(v));
    } else if (const char *v = value("--warmup")) {
      o->warmup = std::max(0, std::atoi(v));
    } else if (const char *v = value("--chunk")) {
      o->chunk = size_t(std::strtoull(v, nullptr, 10));
    } else {
      return false;
    }
  }
  return true;
}

// Something like a rendered frame: a diagonal depth ramp over half the image, background
// elsewhere, different per rank so the merge has real work to do.
lantern::Frame test_frame(int width, int height, int rank) {
  lantern::Frame f(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = f.index(x, y);
      const bool drawn = ((x / 64 + y / 64 + rank) % 2) == 0;
      f.depth[i] = drawn ? float((x + y + 7 * rank) % 1000) / 1000.0f : lantern::kBackgroundDepth;
      for (int c = 0; c < 4; ++c) f.rgba[4 * i + c] = uint8_t(drawn ? 40 * rank + c : 0);
    }
  }
  return f;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  Options options;
  if (!parse_options(argc, argv, &options)) {
    if (rank == 0)
      std::fprintf(stderr,
                   "usage: lantern-bench-composite [--sizes=1024x1024,...] "
                   "[--methods=reduce64,reduce_scatter,binary_swap,direct_send,auto] "
                   "[--reps=7] "
                   "[--warmup=2] [--chunk=pixels]\n");
    MPI_Finalize();
    return 2;
  }
  int status = 0;
  for (const auto &[width, height] : options.sizes) {
    lantern::Frame frame = test_frame(width, height, rank);
    for (const std::string &name : options.methods) {
      lantern::CompositeMethod method;
      if (!lantern::parse_composite_method(name, &method)) {
        if (rank == 0) std::fprintf(stderr, "unknown method %s\n", name.c_str());
        status = 2;
        continue;
      }
      std::vector<double> times;
      std::string ran;
      for (int run = 0; run < options.warmup + options.reps; ++run) {
        MPI_Barrier(MPI_COMM_WORLD);
        lantern::CompositeStats stats;
        const lantern::Status composited =
            lantern::composite_frames(MPI_COMM_WORLD, frame, 0, method, options.chunk, &stats);
        if (!composited.ok()) {
          if (rank == 0) std::fprintf(stderr, "%s: %s\n", name.c_str(), composited.message.c_str());
          status = 1;
          break;
        }
        ran = stats.method;
        if (run >= options.warmup) times.push_back(stats.milliseconds);
      }
      if (rank == 0 && !times.empty())
        std::printf("ranks=%d size=%dx%d method=%s ran=%s median_ms=%.3f min_ms=%.3f runs=%zu\n",
                    ranks, width, height, name.c_str(), ran.c_str(), median(times),
                    *std::min_element(times.begin(), times.end()), times.size());
      std::fflush(stdout);
    }
  }
  MPI_Finalize();
  return status;
}
