#include "bond_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include "bench_timing.h"
#include "core/bricks/brick_bonds.h"
#include "core/camera/camera.h"
#include "core/particles/particle_scan.h"
#include "core/pipeline/rank_draw.h"
#include "core/pipeline/scene_settings.h"
#include "image_metrics.h"
#include "tests/support/bonded_molecules.h"

namespace lantern::bench {
namespace {

using testing::BondedSystem;

// The simple-cubic network of the LAMMPS comparison: n^3 sites of spacing 1 in a periodic cube,
// each bonded to its +x, +y and +z neighbours (LAMMPS's create_bonds many at distance 1).
BondedSystem sc_network(int n) {
  BondedSystem s;
  s.box = n;
  const auto site = [n](int x, int y, int z) {
    return int64_t(((x + n) % n) + n * (((y + n) % n) + n * ((z + n) % n)));
  };
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        s.xyz.insert(s.xyz.end(), {x + 0.0, y + 0.0, z + 0.0});
        s.type.push_back(int32_t((x + y + z) % 2));
        s.id.push_back(int64_t(s.atoms()));
        const int64_t i = site(x, y, z);
        for (const int64_t j : {site(x + 1, y, z), site(x, y + 1, z), site(x, y, z + 1)}) {
          s.bonds.insert(s.bonds.end(), {i, j});
          s.bond_type.push_back(0);
        }
      }
  return s;
}

struct Mode {
  const char *name;
  OcclusionMode occlusion;
  bool frustum;
  double lod_fraction;  // below 1: an approximation; every other mode must match brute force
};

const Mode kModes[] = {
    {"brute_force", OcclusionMode::kNone, false, 1.0}, {"frustum", OcclusionMode::kNone, true, 1.0},
    {"hzb", OcclusionMode::kHzb, true, 1.0},           {"auto", OcclusionMode::kAuto, true, 1.0},
    {"lod_50%", OcclusionMode::kNone, true, 0.5},
};

struct Result {
  std::vector<double> ms;
  CullStats stats;
  Frame frame;
};

}  // namespace

const char *bond_csv_header() {
  return "scene,mode,ms_per_frame,atoms_drawn,atoms_culled_percent,halves_drawn,"
         "halves_culled_percent,diff_px,psnr_db,speedup\n";
}

bool run_bond_bench(const std::string &name, int64_t atoms, int size, int runs, std::ostream &csv,
                    bool *exact) {
  BondedSystem s;
  double atom_radius;
  if (name == "melt") {
    const int beads = 100, chains = int(std::max<int64_t>(1, atoms / beads));
    s = testing::polymer_melt(chains, beads, std::cbrt(double(chains) * beads / 0.85));
    atom_radius = 0.3;
  } else if (name == "network") {
    s = sc_network(std::max(2, int(std::lround(std::cbrt(double(atoms))))));
    atom_radius = 0.25;
  } else {
    return false;
  }
  ParticleDescription pd;
  pd.count = int64_t(s.atoms());
  pd.position = {s.xyz.data(), DataType::kFloat64, 0};
  pd.type = {s.type.data(), DataType::kInt32, 0};
  pd.id = {s.id.data(), DataType::kInt64, 0};
  ParticleArrays particles;
  BondDescription bd;
  bd.count = int64_t(s.bond_count());
  bd.first = {s.bonds.data(), DataType::kInt64, 16};
  bd.second = {s.bonds.data() + 1, DataType::kInt64, 16};
  bd.type = {s.bond_type.data(), DataType::kInt32, 0};
  BondArrays bonds;
  if (Status st = ParticleArrays::validate(pd, &particles); !st.ok()) {
    std::printf("%s: particles: %s\n", name.c_str(), st.message.c_str());
    return true;
  }
  if (Status st = BondArrays::validate(bd, particles, &bonds); !st.ok()) {
    std::printf("%s: bonds: %s\n", name.c_str(), st.message.c_str());
    return true;
  }
  PeriodicBox box;
  box.length = {s.box, s.box, s.box};
  box.periodic = {true, true, true};
  // Bricks and half-bonds: once per step in Lantern, timed apart.
  auto t0 = Clock::now();
  const BrickSet bricks = build_bricks(particles, BrickOptions{});
  const double bricks_ms = ms_since(t0);
  t0 = Clock::now();
  BrickBonds halves;
  build_brick_bonds(particles, bonds, bricks, &box, &halves);
  const double halves_ms = ms_since(t0);

  SceneConfig scene;
  scene.width = scene.height = size;
  scene.radius = atom_radius;
  scene.renderer = RendererChoice::kCpu;
  scene.bonds.enabled = true;
  scene.bonds.radius = 0.15;
  Camera cam;
  if (Status st = make_camera(scene.camera, {0, 0, 0}, {s.box, s.box, s.box}, atom_radius, size,
                              size, &cam);
      !st.ok()) {
    std::printf("%s: camera: %s\n", name.c_str(), st.message.c_str());
    return true;
  }
  std::printf("\n== bonds %s: %zu atoms, %zu bonds (%zu half-bonds), %dx%d, CPU raster\n",
              name.c_str(), s.atoms(), s.bond_count(), halves.half_count(), size, size);
  std::printf("   bricks %.1f ms, half-bonds %.1f ms: once per step, not in the times below\n",
              bricks_ms, halves_ms);
  std::vector<Result> results(std::size(kModes));
  RankDrawScratch scratch;
  for (int run = 0; run < runs; ++run)
    for (size_t m = 0; m < std::size(kModes); ++m) {
      SceneConfig sc = scene;
      sc.culling.occlusion = kModes[m].occlusion;
      sc.culling.frustum = kModes[m].frustum;
      sc.lod.fraction = kModes[m].lod_fraction;
      RankScene rank(particles, bricks, cam, sc);
      rank.bonds = &bonds;
      rank.bond_halves = &halves;
      rank.box = &box;
      Frame scratch_frame;
      Frame &frame = run == 0 ? results[m].frame : scratch_frame;
      RankDraw drawn;
      const auto f0 = Clock::now();
      const Status st = draw_scene_on_rank(rank, &scratch, &frame, &drawn);
      results[m].ms.push_back(ms_since(f0));
      if (!st.ok()) std::printf("%s: %s\n", kModes[m].name, st.message.c_str());
      results[m].stats = drawn.cull;
    }
  std::printf("   %-12s %9s %10s %8s %10s %8s %9s %8s %8s\n", "mode", "ms/frame", "atoms", "culled",
              "half-bonds", "culled", "diff px", "PSNR dB", "speed-up");
  const double brute_ms = median(results[0].ms);
  for (size_t m = 0; m < std::size(kModes); ++m) {
    const Result &r = results[m];
    const ImageError e =
        m == 0 ? ImageError{0, 0, INFINITY, 1.0} : compare_frames(results[0].frame, r.frame);
    if (kModes[m].lod_fraction == 1.0 && e.differing_pixels != 0) {
      std::printf("   %s: %lld pixels differ from brute force in an exact mode\n", kModes[m].name,
                  static_cast<long long>(e.differing_pixels));
      *exact = false;
    }
    const double ms = median(r.ms);
    const int64_t n = int64_t(s.atoms()), h = std::max<int64_t>(r.stats.bonds.halves, 1);
    const double atoms_culled = 100.0 * double(n - r.stats.drawn) / double(n);
    const double halves_culled = 100.0 * double(h - r.stats.bonds.drawn) / double(h);
    std::printf("   %-12s %9.1f %10lld %7.1f%% %10lld %7.1f%% %9lld %8.2f %7.2fx\n", kModes[m].name,
                ms, static_cast<long long>(r.stats.drawn), atoms_culled,
                static_cast<long long>(r.stats.bonds.drawn), halves_culled,
                static_cast<long long>(e.differing_pixels), e.psnr, brute_ms / ms);
    csv << name << ',' << kModes[m].name << ',' << ms << ',' << r.stats.drawn << ',' << atoms_culled
        << ',' << r.stats.bonds.drawn << ',' << halves_culled << ',' << e.differing_pixels << ','
        << e.psnr << ',' << brute_ms / ms << '\n';
  }
  return true;
}

}  // namespace lantern::bench
