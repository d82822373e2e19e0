// lantern-bench-cuts: what a cutting-plane edit costs with the per-brick counts
// (core/culling/brick_cut_counts.h) against classifying every brick from scratch.
//
// For fcc crystals of 1 M and 10 M atoms (lantern-bench's scenes): three planes are set, then a
// fourth is added, removed, and one of the three toggled off and on. "full" classifies every
// brick against every enabled plane (CutPlanes::classify_box, what select_bricks does without
// counts); "incremental" is BrickCutCounts::update after the edit. Medians of --reps runs.
// Every incremental result is checked against the full one (exit 1 on a mismatch).
//
// Usage: lantern-bench-cuts [--sizes=1,10] [--reps=15]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_scenes.h"
#include "core/bricks/brick_set.h"
#include "core/common/ms_since.h"
#include "core/culling/brick_cut_counts.h"
#include "core/culling/cut_planes.h"

namespace lantern::bench {
namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <typename F>
double time_ms(F &&f) {
  const auto t0 = Clock::now();
  f();
  return ms_since(t0);
}

// Classification from scratch; the sides go to *out so the work cannot be skipped.
void full_classification(const BrickSet &bricks, const std::vector<CutPlane> &cuts,
                         std::vector<CutPlanes::Side> *out) {
  const CutPlanes planes(cuts);
  out->resize(bricks.bricks.size());
  for (size_t i = 0; i < bricks.bricks.size(); ++i)
    (*out)[i] = planes.classify_box(bricks.bricks[i].lo, bricks.bricks[i].hi);
}

bool same(const BrickCutCounts &counts, const std::vector<CutPlanes::Side> &full) {
  for (size_t i = 0; i < full.size(); ++i)
    if (counts.side(uint32_t(i)) != full[i]) return false;
  return true;
}

int run(int argc, char **argv) {
  std::vector<int> sizes = {1, 10};
  int reps = 15;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg.rfind("--reps=", 0) == 0) {
      reps = std::max(1, std::atoi(arg.c_str() + 7));
    } else if (arg.rfind("--sizes=", 0) == 0) {
      sizes.clear();
      for (size_t p = 8; p < arg.size();) {
        sizes.push_back(std::atoi(arg.c_str() + p));
        const size_t comma = arg.find(',', p);
        p = comma == std::string::npos ? arg.size() : comma + 1;
      }
    } else {  // a typo must not run the default benchmark as if it were what was asked for
      std::fprintf(stderr,
                   "lantern-bench-cuts: unknown option %s\n"
                   "usage: lantern-bench-cuts [--sizes=1,10] [--reps=15]\n",
                   arg.c_str());
      return 2;
    }
  }
  std::printf("%-9s %8s %-22s %10s %12s %8s %14s\n", "atoms", "bricks", "edit", "ms full",
              "ms increm.", "ratio", "bricks tested");
  bool all_equal = true;
  for (const int millions : sizes) {
    // 4 n^3 atoms: n = 63 gives 1.00 M, n = 136 gives 10.06 M.
    const int n = int(std::cbrt(millions * 1e6 / 4.0) + 0.5);
    const BenchScene scene = fcc_outside(n, 512);
    BrickSet bricks = build_bricks(scene.arrays(), BrickOptions{});
    const double side = n * 1.122462048309373 * 1.4142135623730951;  // crystal edge
    const std::vector<CutPlane> three = {{{0, 1, 0}, 0.6 * side, true},
                                         {{1, 0, 1}, 1.1 * side, true},
                                         {{-1, 0, 0}, -0.2 * side, true}};
    std::vector<CutPlane> four = three;
    four.push_back({{0.3, -0.4, 1.0}, 0.5 * side, true});
    std::vector<CutPlane> toggled = three;
    toggled[1].enabled = false;

    std::vector<CutPlanes::Side> full;
    BrickCutCounts counts;
    std::vector<double> full_ms, scratch_ms;
    for (int r = 0; r < reps; ++r) {
      full_ms.push_back(time_ms([&] { full_classification(bricks, four, &full); }));
      bricks.generation = next_brick_generation();  // as after a refit: counts start over
      scratch_ms.push_back(time_ms([&] { counts.update(bricks, four); }));
    }
    all_equal &= same(counts, full);
    const double full_median = median(full_ms);
    const std::string atoms = std::to_string(scene.type.size() / 1000) + " k";
    std::printf("%-9s %8zu %-22s %10.3f %12.3f %8.2f %14s\n", atoms.c_str(), bricks.bricks.size(),
                "from scratch (4 planes)", full_median, median(scratch_ms),
                full_median / median(scratch_ms), "-");

    struct Edit {
      const char *name;
      const std::vector<CutPlane> *from, *to;
    };
    const Edit edits[] = {{"add 4th plane", &three, &four},
                          {"remove 4th plane", &four, &three},
                          {"toggle a plane off", &three, &toggled},
                          {"toggle it on", &toggled, &three}};
    for (const Edit &e : edits) {
      std::vector<double> inc_ms, ref_ms;
      int64_t tested = 0;
      for (int r = 0; r < reps; ++r) {
        counts.update(bricks, *e.from);
        inc_ms.push_back(time_ms([&] { counts.update(bricks, *e.to); }));
        tested = counts.last_update().bricks_tested;
        ref_ms.push_back(time_ms([&] { full_classification(bricks, *e.to, &full); }));
        all_equal &= same(counts, full);
      }
      std::printf("%-9s %8zu %-22s %10.3f %12.3f %8.1f %14lld\n", atoms.c_str(),
                  bricks.bricks.size(), e.name, median(ref_ms), median(inc_ms),
                  median(ref_ms) / median(inc_ms), static_cast<long long>(tested));
    }
  }
  std::printf("incremental equals full classification: %s\n", all_equal ? "yes" : "NO");
  return all_equal ? 0 : 1;
}

}  // namespace
}  // namespace lantern::bench

int main(int argc, char **argv) {
  return lantern::bench::run(argc, argv);
}
