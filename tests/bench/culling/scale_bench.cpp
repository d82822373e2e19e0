#include "scale_bench.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_timing.h"
#include "core/pipeline/runtime.h"

namespace lantern::bench {
namespace {

constexpr double kNearestNeighbour = 1.122462048309373;  // 2^(1/6), as bench_scenes.cpp
const double kLattice = kNearestNeighbour * std::sqrt(2.0);

// This rank's particles: the "simulation's" arrays, owned here.
struct Share {
  std::vector<double> xyz;
  std::vector<int32_t> type;
  int64_t global = 0;  // particles over all ranks
  std::string note;
  int64_t count() const { return int64_t(type.size()); }
};

// A hash of a particle's global index and a salt to [0, 1): the same particle gets the same
// numbers whatever the rank count.
double unit_hash(uint64_t i, uint64_t salt) {
  uint64_t h = (i + 1) * 0x9e3779b97f4a7c15ull ^ salt * 0xbf58476d1ce4e5b9ull;
  h ^= h >> 31, h *= 0x94d049bb133111ebull, h ^= h >> 29;
  return double(h >> 11) * (1.0 / 9007199254740992.0);
}

// The fcc crystal of n^3 cells (4 n^3 atoms, lattice order, z slowest, as bench_scenes.cpp's
// fcc()), this rank's slab of z planes; with `gas`, plus this rank's share of a gas of an eighth
// of the crystal's atom count in twice its volume beside it (bench_scenes.cpp's heterogeneous).
Share make_share(int n, bool gas, int rank, int ranks) {
  Share s;
  const int z0 = int(int64_t(n) * rank / ranks), z1 = int(int64_t(n) * (rank + 1) / ranks);
  const int64_t solid = 4LL * n * n * (z1 - z0);
  const int64_t gas_all = gas ? 4LL * n * n * n / 8 : 0;
  const int64_t g0 = gas_all * rank / ranks, g1 = gas_all * (rank + 1) / ranks;
  s.xyz.reserve(size_t(3 * (solid + g1 - g0)));  // exact: no growth past the arrays' size
  s.type.reserve(size_t(solid + g1 - g0));
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int z = z0; z < z1; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        for (int b = 0; b < 4; ++b) {
          s.xyz.insert(s.xyz.end(), {(x + basis[b][0]) * kLattice, (y + basis[b][1]) * kLattice,
                                     (z + basis[b][2]) * kLattice});
          s.type.push_back(int32_t(((x / 8) + (y / 8) + (z / 8)) % 4));  // colored domains
        }
  const double side = n * kLattice;
  for (int64_t k = g0; k < g1; ++k) {
    s.xyz.insert(s.xyz.end(), {-2.0 * side * unit_hash(uint64_t(k), 1) - 1.0,
                               side * unit_hash(uint64_t(k), 2), side * unit_hash(uint64_t(k), 3)});
    s.type.push_back(4);
  }
  s.global = 4LL * n * n * n + gas_all;
  s.note = "fcc " + std::to_string(n) + "^3 cells (" + std::to_string(4LL * n * n * n) + " atoms)";
  if (gas) s.note += " beside a gas of " + std::to_string(gas_all) + " atoms in twice its volume";
  return s;
}

// Cells per side for about `millions` particles in all: 4 n^3 (fcc) or 4.5 n^3 (with the gas).
int cells_for(double millions, bool gas) {
  return int(std::lround(std::cbrt(millions * 1e6 / (gas ? 4.5 : 4.0))));
}

// A thermal step: every coordinate moves by up to +-0.01 (0.9 % of the neighbour distance).
void move_a_little(Share *s, int64_t first_global, int step) {
  for (int64_t i = 0; i < s->count(); ++i)
    for (int c = 0; c < 3; ++c)
      s->xyz[size_t(3 * i + c)] +=
          0.02 * (unit_hash(uint64_t(first_global + i), uint64_t(3 * step + c + 7)) - 0.5);
}

// One streaming pass over the positions: every byte read once, four independent sums so that
// memory, not the adder's latency, sets the pace.
double streaming_pass_ms(const std::vector<double> &xyz) {
  const auto t0 = Clock::now();
  double a = 0, b = 0, c = 0, d = 0;
  const double *p = xyz.data();
  const size_t n = xyz.size();
  size_t i = 0;
  for (; i + 4 <= n; i += 4) a += p[i], b += p[i + 1], c += p[i + 2], d += p[i + 3];
  for (; i < n; ++i) a += p[i];
  const double ms = ms_since(t0);
  static volatile double sink;
  sink = a + b + c + d;
  return ms;
}

// The process's resident size and high-water mark (KiB, /proc/self/status), and the resident
// pages lazily freed (KiB, LazyFree of /proc/self/smaps_rollup): blocks Lantern keeps for the next
// frame, which the kernel takes back whenever it needs memory (core/common/page_allocator.h).
struct Memory {
  double rss_kib = 0, hwm_kib = 0, lazy_kib = 0;
  double in_use_kib() const { return rss_kib - lazy_kib; }
};
Memory memory_now() {
  Memory m;
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) m.rss_kib = std::stod(line.substr(6));
    if (line.rfind("VmHWM:", 0) == 0) m.hwm_kib = std::stod(line.substr(6));
  }
  std::ifstream rollup("/proc/self/smaps_rollup");
  for (std::string line; std::getline(rollup, line);)
    if (line.rfind("LazyFree:", 0) == 0) m.lazy_kib = std::stod(line.substr(9));
  return m;
}
// Resets VmHWM to the current resident size (Linux >= 4.0); false where that is refused.
bool reset_high_water_mark() {
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
  f.flush();
  return bool(f);
}

double max_over_ranks(double v) {
  double m = 0;
  MPI_Allreduce(&v, &m, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return m;
}

// What rank 0 reads back from the step's stats line.
struct StepStats {
  double bricks_ms = 0, cull_ms = 0, draw_ms = 0, composite_ms = 0, write_ms = 0, scene_ms = 0,
         total_ms = 0;
  std::string bricks, renderer, occlusion;
  int64_t drawn = 0;
};
StepStats last_stats(const std::string &path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  StepStats s;
  if (last.empty()) return s;
  const auto j = nlohmann::json::parse(last, nullptr, false);
  if (j.is_discarded() || !j.contains("scenes") || j["scenes"].empty()) return s;
  const auto &sc = j["scenes"][0];
  const auto &ms = sc["ms"];
  s.bricks_ms = ms.value("bricks", 0.0);
  s.cull_ms = ms.value("cull", 0.0);
  s.draw_ms = ms.value("draw", 0.0);
  s.composite_ms = ms.value("composite", 0.0);
  s.write_ms = ms.value("write", 0.0);
  s.scene_ms = ms.value("total", 0.0);
  s.total_ms = j["ms"].value("total", 0.0);
  s.bricks = sc.value("bricks", "");
  s.renderer = sc.value("renderer", "");
  s.occlusion = sc.value("occlusion", "");
  s.drawn = sc["particles"].value("drawn", int64_t(0));
  return s;
}

struct Row {
  std::string scene;
  int64_t particles = 0, local = 0;
  double pass_ms = 0, first_ms = 0, build_ms = 0, later_ms = 0, refit_ms = 0, cull_ms = 0,
         composite_ms = 0, write_ms = 0, peak_bpp = 0, retained_bpp = 0, peak_mib = 0, hwm_mib = 0,
         lazy_mib = 0;
  std::string how, renderer, occlusion;
};

// Renders one scene at one size; fills *row on rank 0. False if a step failed.
bool run_one(const ScaleOptions &opt, const std::string &scene, double millions, Row *row) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const bool gas = scene == "heterogeneous";
  const int n = cells_for(millions, gas);
  Share share = make_share(n, gas, rank, ranks);
  int64_t first_global = 0, local = share.count();
  MPI_Exscan(&local, &first_global, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  if (rank == 0) first_global = 0;
  const std::string name = scene + "_" + std::to_string(share.global / 1000000) + "M";
  const std::string stats = opt.out + "/scale_" + name + "_stats.jsonl";
  if (rank == 0) std::remove(stats.c_str());
  const std::string yaml =
      "stats: '" + stats + "'\nscenes:\n  - name: " + name +
      "\n    width: " + std::to_string(opt.size) + "\n    height: " + std::to_string(opt.size) +
      "\n    output: {pattern: '" + opt.out + "/scale_{scene}_{step:02d}.png'}\n";
  std::unique_ptr<Runtime> rt;
  if (Status s = Runtime::open(yaml, MPI_COMM_WORLD, &rt); !s.ok()) {
    if (rank == 0) std::printf("   %s: %s\n", name.c_str(), s.message.c_str());
    return false;
  }
  ParticleDescription d{};
  d.count = share.count();
  d.position = {share.xyz.data(), DataType::kFloat64, 0};
  d.type = {share.type.data(), DataType::kInt32, 0};
  if (Status s = rt->publish(d); !s.ok()) {
    std::printf("   rank %d: publish: %s\n", rank, s.message.c_str());
    return false;
  }
  if (rank == 0)
    std::printf("\n== %s: %s, %lld particles on %d ranks, %dx%d, %d later frames\n", name.c_str(),
                share.note.c_str(), static_cast<long long>(share.global), ranks, opt.size, opt.size,
                opt.runs);
  MPI_Barrier(MPI_COMM_WORLD);
  const bool hwm_reset = reset_high_water_mark();
  const Memory before = memory_now();  // arrays, libraries, the runtime: not Lantern's frames
  bool ok = true;
  std::vector<double> pass, frame, refit, cull, composite, write;
  StepStats first;
  for (int step = 0; step <= opt.runs; ++step) {
    if (step > 0) move_a_little(&share, first_global, step);
    MPI_Barrier(MPI_COMM_WORLD);
    pass.push_back(streaming_pass_ms(share.xyz));
    MPI_Barrier(MPI_COMM_WORLD);
    const auto t0 = Clock::now();
    if (Status s = rt->execute(step, double(step)); !s.ok()) {
      if (rank == 0) std::printf("   step %d: %s\n", step, s.message.c_str());
      ok = false;
      break;
    }
    const double ms = max_over_ranks(ms_since(t0));
    const StepStats st = rank == 0 ? last_stats(stats) : StepStats{};
    if (step == 0) {
      row->first_ms = ms;
      first = st;
    } else {
      frame.push_back(ms);
      refit.push_back(st.bricks_ms);
      cull.push_back(st.cull_ms - st.bricks_ms + st.draw_ms);
      composite.push_back(st.composite_ms);
      write.push_back(st.write_ms);
      if (rank == 0 && st.bricks != "refit")
        std::printf("   step %d: bricks %s (not refit)\n", step, st.bricks.c_str());
    }
  }
  const Memory after = memory_now();
  (void)rt->finish();
  rt.reset();
  if (!ok) return false;
  const double kib = 1024.0;
  const double peak = max_over_ranks((after.hwm_kib - before.rss_kib) * kib / double(local));
  // Retained: resident pages in use (lazily freed ones, which the kernel takes back on demand,
  // are counted apart).
  const double kept =
      max_over_ranks((after.in_use_kib() - before.in_use_kib()) * kib / double(local));
  const double lazy_mib = max_over_ranks(after.lazy_kib / kib);
  const double peak_mib = max_over_ranks((after.hwm_kib - before.rss_kib) / kib);
  const double hwm_mib = max_over_ranks(after.hwm_kib / kib);
  // Every rank's retained MiB and bytes per particle: which rank the maximum above comes from.
  const double mine[2] = {(after.in_use_kib() - before.in_use_kib()) / kib,
                          (after.in_use_kib() - before.in_use_kib()) * kib / double(local)};
  std::vector<double> each(rank == 0 ? 2 * size_t(ranks) : 0);
  MPI_Gather(mine, 2, MPI_DOUBLE, each.data(), 2, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (rank != 0) return true;
  std::printf("   retained by rank (MiB, B/p):");
  for (int r = 0; r < ranks; ++r)
    std::printf(" %d: %.1f, %.2f;", r, each[2 * size_t(r)], each[2 * size_t(r) + 1]);
  std::printf("\n");
  if (!hwm_reset) std::printf("   (VmHWM could not be reset: peak includes the generation)\n");
  row->scene = name;
  row->particles = share.global;
  row->local = local;
  row->pass_ms = median(pass);
  row->build_ms = first.bricks_ms;
  row->how = first.bricks;
  row->later_ms = median(frame);
  row->refit_ms = median(refit);
  row->cull_ms = median(cull);
  row->composite_ms = median(composite);
  row->write_ms = median(write);
  row->peak_bpp = peak;
  row->retained_bpp = kept;
  row->peak_mib = peak_mib;
  row->hwm_mib = hwm_mib;
  row->lazy_mib = lazy_mib;
  row->renderer = first.renderer;
  row->occlusion = first.occlusion;
  std::printf("   renderer %s, occlusion %s, drawn %lld\n", first.renderer.c_str(),
              first.occlusion.c_str(), static_cast<long long>(first.drawn));
  std::printf("   pass ms per frame (rank 0):");
  for (const double p : pass) std::printf(" %.1f", p);
  std::printf("\n   frame ms (slowest rank): first %.1f, later", row->first_ms);
  for (const double f : frame) std::printf(" %.1f", f);
  std::printf("\n");
  return true;
}

}  // namespace

bool run_scale_bench(const ScaleOptions &opt) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  std::vector<Row> rows;
  bool ok = true;
  for (const std::string &scene : opt.scenes)
    for (const double m : opt.millions) {
      Row row;
      ok &= run_one(opt, scene, m, &row);
      if (rank == 0 && !row.scene.empty()) rows.push_back(row);
      std::fflush(stdout);
    }
  if (rank != 0) return ok;
  std::printf(
      "\nPer rank, rank 0's stats (frame: the slowest rank's execute); pass: one streaming pass "
      "over the rank's positions, median over the frames; ratios to it. Memory: per local "
      "particle, the slowest rank, above the resident size before the first frame; retained "
      "leaves out the lazily freed pages kept for the next frame (lazy MiB, which the kernel "
      "takes back whenever it needs memory).\n");
  std::printf(
      "| scene | particles | per rank | pass ms | first frame ms | build ms | build ns/p | "
      "build/pass | later frame ms | refit ms | refit/pass | cull+draw ms | composite ms "
      "| png ms | peak B/p | retained B/p | peak MiB | VmHWM MiB | lazy MiB |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  const std::string csv_path = opt.out + "/scale_bench.csv";
  std::ofstream csv(csv_path);
  csv << "scene,particles,per_rank,pass_ms,first_frame_ms,build_ms,build_ns_per_particle,"
         "build_over_pass,later_frame_ms,refit_ms,refit_over_pass,cull_draw_ms,composite_ms,"
         "png_ms,peak_bytes_per_particle,retained_bytes_per_particle,peak_mib,vmhwm_mib,"
         "lazily_freed_mib,renderer\n";
  for (const Row &r : rows) {
    const double ns = 1e6 / double(r.local);
    std::printf(
        "| %s | %lld | %lld | %.1f | %.1f | %.1f | %.1f | %.2fx | %.1f | %.1f | %.2fx | %.1f "
        "| %.1f | %.1f | %.1f | %.2f | %.0f | %.0f | %.1f |\n",
        r.scene.c_str(), static_cast<long long>(r.particles), static_cast<long long>(r.local),
        r.pass_ms, r.first_ms, r.build_ms, r.build_ms * ns, r.build_ms / r.pass_ms, r.later_ms,
        r.refit_ms, r.refit_ms / r.pass_ms, r.cull_ms, r.composite_ms, r.write_ms, r.peak_bpp,
        r.retained_bpp, r.peak_mib, r.hwm_mib, r.lazy_mib);
    csv << r.scene << ',' << r.particles << ',' << r.local << ',' << r.pass_ms << ',' << r.first_ms
        << ',' << r.build_ms << ',' << r.build_ms * ns << ',' << r.build_ms / r.pass_ms << ','
        << r.later_ms << ',' << r.refit_ms << ',' << r.refit_ms / r.pass_ms << ',' << r.cull_ms
        << ',' << r.composite_ms << ',' << r.write_ms << ',' << r.peak_bpp << ',' << r.retained_bpp
        << ',' << r.peak_mib << ',' << r.hwm_mib << ',' << r.lazy_mib << ',' << r.renderer << '\n';
  }
  csv.close();
  if (csv.fail()) {
    std::fprintf(stderr, "lantern-bench: cannot write %s\n", csv_path.c_str());
    return false;
  }
  std::printf("\nwrote %s\n", csv_path.c_str());
  return ok;
}

}  // namespace lantern::bench
