// lantern-bench-runs: listing a brick set's index runs (runs_of_owners, core/bricks/index_runs.h)
// with the AVX2 listing against the SSE2 one, on the owners of real brick builds.
//
// For each size (an fcc crystal of 4 n^3 atoms) and each order of the positions - `lattice` (the
// generator's cell by cell order), `bins` (jittered by up to 0.1 and sorted into bins of 1.5
// sigma, z then y then x, as LAMMPS's atom sorting leaves a crystal) - it builds the bricks once,
// then lists the runs of the owners both ways, as the refit does (brick numbers) and as the build
// does (the bricks' first slots), alternating which goes first, and checks that both give the same
// runs and bits. Prints the median, minimum and maximum ms of each and their ratio.
//
//   build/tests/bench/culling/lantern-bench-runs [--cells 107,168] [--reps 9]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench_scenes.h"
#include "core/bricks/brick_set.h"
#include "core/bricks/index_runs.h"
#include "core/particles/particle_arrays.h"
#include "core/particles/particle_description.h"

namespace {

using lantern::Brick;
using lantern::IndexRun;
using lantern::IndexRuns;
using lantern::kNoBrick;
using lantern::PageVector;
using Clock = std::chrono::steady_clock;

// An fcc crystal of n^3 cells (bench_scenes.h) in the generator's order, or jittered and sorted
// into bins (the order LAMMPS's atom_modify sort leaves).
std::vector<double> fcc(int n, bool bins) {
  std::vector<double> xyz = lantern::bench::fcc_outside(n, 64).xyz;
  if (!bins) return xyz;
  const auto count = int64_t(xyz.size() / 3);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> jitter(-0.1, 0.1);
  for (double &v : xyz) v += jitter(rng);
  const double bin = 1.5;
  const auto side = int64_t(*std::max_element(xyz.begin(), xyz.end()) / bin) + 3;
  std::vector<int64_t> key(static_cast<size_t>(count)), idx(static_cast<size_t>(count));
  for (int64_t i = 0; i < count; ++i) {
    const auto cell = [&](int d) { return int64_t(std::floor(xyz[size_t(3 * i + d)] / bin)) + 1; };
    key[size_t(i)] = (cell(2) * side + cell(1)) * side + cell(0);
    idx[size_t(i)] = i;
  }
  std::stable_sort(idx.begin(), idx.end(),
                   [&](int64_t p, int64_t q) { return key[size_t(p)] < key[size_t(q)]; });
  std::vector<double> sorted(xyz.size());
  for (int64_t i = 0; i < count; ++i)
    for (int d = 0; d < 3; ++d) sorted[size_t(3 * i + d)] = xyz[size_t(3 * idx[size_t(i)] + d)];
  return sorted;
}

bool same_runs(const IndexRuns &a, const PageVector<uint64_t> &abits, const IndexRuns &b,
               const PageVector<uint64_t> &bbits) {
  if (a.size() != b.size() || abits != bbits) return false;
  for (size_t k = 0; k < a.size(); ++k) {
    const IndexRun x = a[k], y = b[k];
    if (x.first != y.first || x.brick != y.brick || x.other != y.other) return false;
  }
  return true;
}

struct Stats {
  double median, min, max;
};
Stats stats(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return {v[v.size() / 2], v.front(), v.back()};
}

// Lists the runs of `owner` reps times each way; false if the two ways differ.
bool compare(const char *order, const char *owners, const std::vector<uint32_t> &owner,
             int64_t held, const std::vector<Brick> *by, int reps) {
  std::vector<double> ms[2];
  IndexRuns runs[2];
  PageVector<uint64_t> bits[2];
  for (int r = 0; r < reps; ++r)
    for (int k = 0; k < 2; ++k) {
      const int way = (r + k) % 2;  // 0: SSE2, 1: AVX2; which goes first alternates
      lantern::runs_avx2_enabled() = way == 1;
      const auto t0 = Clock::now();
      runs[way] =
          lantern::runs_of_owners(owner.data(), int64_t(owner.size()), held, &bits[way], by);
      ms[way].push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
  lantern::runs_avx2_enabled() = true;
  if (!same_runs(runs[0], bits[0], runs[1], bits[1])) {
    std::fprintf(stderr, "lantern-bench-runs: %s %s: the two listings differ\n", order, owners);
    return false;
  }
  const Stats s = stats(ms[0]), v = stats(ms[1]);
  const double mean = runs[0].empty() ? 0.0 : double(owner.size()) / double(runs[0].size() - 1);
  std::printf("| %s | %s | %zu | %zu | %.1f | %.2f (%.2f-%.2f) | %.2f (%.2f-%.2f) | %.2f |\n",
              order, owners, owner.size(), runs[0].size(), mean, s.median, s.min, s.max, v.median,
              v.min, v.max, v.median / s.median);
  return true;
}

}  // namespace

int main(int argc, char **argv) {
  std::vector<int> cells{107};
  int reps = 9;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--cells" && i + 1 < argc) {
      cells.clear();
      std::stringstream ss(argv[++i]);
      for (std::string s; std::getline(ss, s, ',');) cells.push_back(std::stoi(s));
    } else if (a == "--reps" && i + 1 < argc) {
      reps = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: lantern-bench-runs [--cells 107,168] [--reps 9]\n");
      return 2;
    }
  }
  if (!__builtin_cpu_supports("avx2")) {
    std::fprintf(stderr, "lantern-bench-runs: this processor has no AVX2: nothing to compare\n");
    return 77;  // CTest's skip
  }
  std::printf(
      "| order | owners | particles | runs | mean run | SSE2 ms | AVX2 ms | AVX2 / SSE2 |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const int n : cells)
    for (const bool bins : {false, true}) {
      const std::vector<double> xyz = fcc(n, bins);
      lantern::ParticleDescription p{};
      p.count = int64_t(xyz.size() / 3);
      p.position = {xyz.data(), lantern::DataType::kFloat64, 0};
      lantern::ParticleArrays arrays;
      if (!lantern::ParticleArrays::validate(p, &arrays).ok()) return 1;
      const lantern::BrickSet set = lantern::build_bricks(arrays, lantern::BrickOptions{});
      std::vector<uint32_t> number(size_t(p.count), kNoBrick), first(size_t(p.count), kNoBrick);
      for (size_t b = 0; b < set.bricks.size(); ++b)
        for (uint32_t k = 0; k < set.bricks[b].count; ++k) {
          const uint32_t i = set.order[set.bricks[b].first + k];
          number[i] = uint32_t(b);
          first[i] = set.bricks[b].first;
        }
      const char *order = bins ? "bins" : "lattice";
      const int64_t held = set.particle_count();
      if (!compare(order, "brick numbers (refit)", number, held, nullptr, reps) ||
          !compare(order, "first slots (build)", first, held, &set.bricks, reps))
        return 1;
    }
  return 0;
}
