#include "bench_scenes.h"

#include <array>
#include <cmath>
#include <random>
#include <sstream>
#include <string>

#ifdef LANTERN_BENCH_HAS_MINI_MD
#include <mpi.h>

#include "atoms.h"
#include "domain_decomposition.h"
#include "run_config.h"
#include "scenes.h"
#endif

namespace lantern::bench {
namespace {

constexpr double kNearestNeighbour = 1.122462048309373;  // 2^(1/6)
const double kLattice = kNearestNeighbour * std::sqrt(2.0);

// fcc of n x n x nz cells.
BenchScene fcc(int n, int nz) {
  BenchScene s;
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  s.xyz.reserve(size_t(12) * n * n * nz);
  s.type.reserve(size_t(4) * n * n * nz);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        for (int b = 0; b < 4; ++b) {
          s.xyz.insert(s.xyz.end(), {(x + basis[b][0]) * kLattice, (y + basis[b][1]) * kLattice,
                                     (z + basis[b][2]) * kLattice});
          s.type.push_back(int32_t(((x / 8) + (y / 8) + (z / 8)) % 4));  // colored domains
        }
  s.config.radius = 0.5;
  s.config.color.by = ColorBy::kType;
  return s;
}

BenchScene fcc(int n) {
  return fcc(n, n);
}

}  // namespace

ParticleArrays BenchScene::arrays() const {
  ParticleDescription p{};
  p.count = int64_t(type.size());
  p.position = {xyz.data(), DataType::kFloat64, 0};
  p.type = {type.data(), DataType::kInt32, 0};
  if (!radius.empty()) p.radius = {radius.data(), DataType::kFloat64, 0};
  ParticleArrays a;
  ParticleArrays::validate(p, &a);
  return a;
}

BenchScene fcc_outside(int n, int size) {
  BenchScene s = fcc(n);
  s.name = "fcc_" + std::to_string(4LL * n * n * n / 1000000) + "M_outside";
  s.note = "fcc " + std::to_string(n) + "^3 cells (" + std::to_string(s.type.size()) +
           " atoms), r 0.5, nn 1.12, camera outside (azimuth 30, elevation 20)";
  s.config.width = s.config.height = size;
  return s;
}

BenchScene fcc_inside(int n, int size) {
  BenchScene s = fcc(n);
  s.name = "fcc_" + std::to_string(4LL * n * n * n / 1000000) + "M_inside";
  const double side = n * kLattice;
  CameraConfig &cam = s.config.camera;
  cam.fov_y = 70.0;
  // Off the lattice planes, in a lattice-free channel, looking across the crystal.
  cam.position = std::array<double, 3>{0.31 * side + 0.27, 0.43 * side + 0.61, 0.52 * side + 0.13};
  cam.look_at = {0.9 * side, 0.8 * side, 0.6 * side};
  cam.up = {0, 0, 1};
  s.note = "fcc " + std::to_string(n) + "^3 cells (" + std::to_string(s.type.size()) +
           " atoms), camera inside the crystal, fov 70";
  s.config.width = s.config.height = size;
  return s;
}

BenchScene thin_film(int n, int size) {
  BenchScene s = fcc(n, 2);
  s.name = "film_" + std::to_string(s.type.size() / 1000) + "k";
  s.note = "thin fcc film of " + std::to_string(n) + " x " + std::to_string(n) +
           " x 2 cells (4 atomic layers, " + std::to_string(s.type.size()) +
           " atoms), r 0.5, camera outside (azimuth 30, elevation 20)";
  s.config.width = s.config.height = size;
  return s;
}

BenchScene heterogeneous(int n, int size) {
  BenchScene s = fcc(n);
  const size_t solid = s.type.size();
  // A gas of the solid's atom count / 8 spread over a box twice the solid's width beside it
  // (Ibrahim et al. 2022, Fig. 2: the sparse crown next to the dense block): density about 1/64 the
  // solid's.
  const double side = n * kLattice;
  std::mt19937_64 rng(20240521);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (size_t k = 0; k < solid / 8; ++k) {
    s.xyz.insert(s.xyz.end(), {-2.0 * side * u(rng) - 1.0, side * u(rng), side * u(rng)});
    s.type.push_back(4);
  }
  s.name = "heterogeneous_" + std::to_string(s.type.size() / 1000) + "k";
  s.note = "fcc " + std::to_string(n) + "^3 cells (" + std::to_string(solid) +
           " atoms) beside a gas of " + std::to_string(s.type.size() - solid) +
           " atoms in twice its volume (Ibrahim et al. 2022, Fig. 2)";
  s.config.width = s.config.height = size;
  return s;
}

BenchScene clustered_cloud(int64_t n, int size) {
  BenchScene s;
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> u(0.0, 200.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::array<std::array<double, 4>, 8> blobs;  // centre and sigma
  for (auto &b : blobs)
    b = {30.0 + 0.7 * u(rng), 30.0 + 0.7 * u(rng), 30.0 + 0.7 * u(rng), 2.0 + 0.06 * u(rng)};
  s.xyz.reserve(size_t(3 * n));
  s.type.reserve(size_t(n));
  for (int64_t i = 0; i < n; ++i) {
    if (i % 5 == 4) {  // the sparse background
      s.xyz.insert(s.xyz.end(), {u(rng), u(rng), u(rng)});
      s.type.push_back(0);
      continue;
    }
    const auto &b = blobs[size_t(i % 8)];
    s.xyz.insert(s.xyz.end(),
                 {b[0] + b[3] * gauss(rng), b[1] + b[3] * gauss(rng), b[2] + b[3] * gauss(rng)});
    s.type.push_back(int32_t(1 + i % 3));
  }
  s.name = "clustered_" + std::to_string(n / 1000000) + "M";
  s.note = std::to_string(n) +
           " particles: 80 % in 8 Gaussian blobs (sigma 2-14), 20 % uniform "
           "in a 200^3 cube, r 0.5";
  s.config.radius = 0.5;
  s.config.color.by = ColorBy::kType;
  s.config.width = s.config.height = size;
  return s;
}

bool mini_md_scene(const std::string &kind, int cells, int size, BenchScene *out,
                   std::string *why) {
#ifdef LANTERN_BENCH_HAS_MINI_MD
  mini_md::RunConfig cfg;
  cfg.scene = kind == "droplet" ? mini_md::SceneKind::kDroplet : mini_md::SceneKind::kVoidImpact;
  cfg.cells = cells;
  cfg.print_thermo = false;
  const mini_md::SceneSetup setup = mini_md::define_scene(cfg);
  mini_md::DomainDecomposition dd(MPI_COMM_WORLD, setup.box, cfg.cutoff + cfg.skin);
  mini_md::Atoms atoms;
  mini_md::create_scene_atoms(cfg, setup, dd, atoms);
  BenchScene s;
  s.name = kind;
  s.note = "mini_md start configuration: " + setup.description + " (" +
           std::to_string(atoms.nlocal) + " atoms)";
  s.xyz.resize(size_t(atoms.nlocal) * 3);
  for (int i = 0; i < atoms.nlocal; ++i)
    for (int c = 0; c < 3; ++c) s.xyz[size_t(3) * i + c] = atoms.x[size_t(i)][size_t(c)];
  s.type.assign(atoms.type.begin(), atoms.type.begin() + atoms.nlocal);
  s.config.radius = 0.5;
  s.config.color.by = ColorBy::kType;
  s.config.width = s.config.height = size;
  if (kind == "void_impact") {
    // The voids are centred on y = Ly/2: cut there to show them (exercises the cut-plane hook).
    CutPlane cut;
    cut.normal = {0, 1, 0};
    cut.offset = 0.5 * (setup.box.lo[1] + setup.box.hi[1]);
    s.config.cuts.push_back(cut);
    s.config.camera.azimuth = 70.0;  // from +y, facing the cut
    s.config.camera.elevation = 15.0;
    s.note += ", cut at y = Ly/2";
  }
  *out = std::move(s);
  return true;
#else
  (void)kind, (void)cells, (void)size, (void)out;
  *why = "mini_md is not built (LANTERN_BUILD_MINI_MD=OFF)";
  return false;
#endif
}

bool assign_radii(const std::string &mix, BenchScene *s) {
  const double r = s->config.radius;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  if (mix == "uniform") {
    s->radius.resize(s->type.size());
    for (double &v : s->radius) v = r * (0.3 + 0.9 * u(rng));
    s->note += ", radii uniform in [0.3, 1.2] r";
  } else if (mix == "bimodal") {
    s->radius.resize(s->type.size());
    for (double &v : s->radius) v = r * (u(rng) < 0.5 ? 0.5 : 1.2);
    s->note += ", radii bimodal: half 0.5 r, half 1.2 r";
  } else {
    return false;
  }
  s->name += "_" + mix;
  s->config.per_particle_radius = true;
  return true;
}

void keep_rank_block(BenchScene *s, int rank, int ranks) {
  const size_t n = s->type.size(), lo = n * size_t(rank) / size_t(ranks),
               hi = n * size_t(rank + 1) / size_t(ranks);
  s->xyz = std::vector<double>(s->xyz.begin() + 3 * lo, s->xyz.begin() + 3 * hi);
  s->type = std::vector<int32_t>(s->type.begin() + lo, s->type.begin() + hi);
}

std::string scene_yaml_keys(const BenchScene &s) {
  const auto number = [](double v) {
    std::ostringstream text;
    text.precision(17);
    text << v;
    return text.str();
  };
  const SceneConfig &c = s.config;
  std::string y =
      "    width: " + std::to_string(c.width) + "\n    height: " + std::to_string(c.height) +
      "\n    radius: " + number(c.radius) + "\n    camera: {azimuth: " + number(c.camera.azimuth) +
      ", elevation: " + number(c.camera.elevation) + ", zoom: " + number(c.camera.zoom) +
      "}\n    color: {by: type}\n";
  if (!c.cuts.empty()) {
    y += "    cut_planes:\n";
    for (const CutPlane &p : c.cuts)
      y += "      - {normal: [" + number(p.normal[0]) + ", " + number(p.normal[1]) + ", " +
           number(p.normal[2]) + "], offset: " + number(p.offset) + "}\n";
  }
  return y;
}

}  // namespace lantern::bench
