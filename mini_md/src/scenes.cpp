#include "scenes.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "counter_rng.h"
#include "lattice.h"
#include "md_error.h"
#include "velocity_init.h"

namespace mini_md {

namespace {

constexpr double kLiquidDensity = 0.8442;
constexpr double kSolidDensity = 1.07;  // near zero pressure for the LJ crystal at low T
constexpr double kGasDensity = 0.02;
constexpr int32_t kTypeTarget = 1;
constexpr int32_t kTypeFlyer = 2;

// Layout of the void-impact scene in units of the lattice constant, derived from --cells.
struct ImpactLayout {
  int n = 1;            // lateral cells and target thickness in cells
  int flyer_cells = 2;  // flyer thickness in cells
  double below = 2;     // vacuum below the target (room for spall before the wall)
  double gap = 1.5;     // target top cell to flyer bottom cell: planes 2a apart, beyond cutoff
  double above = 2;     // vacuum above the flyer

  explicit ImpactLayout(int cells)
      : n(cells), flyer_cells(std::max(2, cells / 4)), below(std::max(2, cells / 2)) {}
  double height() const { return below + n + gap + flyer_cells + above; }
};

struct Void {
  Vec3 centre;
  double radius;
};

// Five voids: three centred on the mid-plane y = side/2 (two near the struck face, one deeper
// between them), so a cut plane there sections them all, and two off-plane near the face.
std::vector<Void> impact_voids(const ImpactLayout &layout, double a) {
  const double side = layout.n * a;
  const double top = (layout.below + layout.n) * a;
  const double r = std::max(1.5 * a, 0.1 * side);
  return {{{0.25 * side, 0.50 * side, top - 0.30 * side}, r},
          {{0.75 * side, 0.50 * side, top - 0.30 * side}, r},
          {{0.50 * side, 0.50 * side, top - 0.65 * side}, r},
          {{0.50 * side, 0.15 * side, top - 0.35 * side}, r},
          {{0.50 * side, 0.85 * side, top - 0.35 * side}, r}};
}

bool inside_any(const Vec3 &p, const std::vector<Void> &voids) {
  for (const Void &v : voids) {
    const double dx = p[0] - v.centre[0], dy = p[1] - v.centre[1], dz = p[2] - v.centre[2];
    if (dx * dx + dy * dy + dz * dz < v.radius * v.radius) return true;
  }
  return false;
}

void apply_boundary_override(const std::string &spec, Box &box) {
  if (spec.empty()) return;
  if (spec.size() != 3 || spec.find_first_not_of("pf") != std::string::npos) {
    throw MdError(
        "--boundary must be three letters from {p, f} (periodic, fixed reflecting wall), got '" +
        spec + "'");
  }
  for (int d = 0; d < 3; ++d) box.periodic[d] = spec[d] == 'p';
}

void create_lattice(const SceneSetup &s, int cells, const DomainDecomposition &dd, Atoms &atoms) {
  FccBlock block;
  block.a = fcc_lattice_constant(s.density);
  block.n[0] = block.n[1] = block.n[2] = cells;
  for_each_fcc_site(block, dd.sub_lo(), dd.sub_hi(), [&](const Vec3 &p, int64_t index) {
    atoms.add_owned(p, Vec3{0, 0, 0}, index + 1, 1);
  });
}

void create_void_impact(const SceneSetup &s, int cells, const DomainDecomposition &dd,
                        Atoms &atoms) {
  const ImpactLayout layout(cells);
  const double a = fcc_lattice_constant(s.density);
  const std::vector<Void> voids = impact_voids(layout, a);
  FccBlock target;
  target.a = a;
  target.origin = {0, 0, layout.below * a};
  target.n[0] = target.n[1] = target.n[2] = cells;
  for_each_fcc_site(target, dd.sub_lo(), dd.sub_hi(), [&](const Vec3 &p, int64_t index) {
    if (!inside_any(p, voids)) atoms.add_owned(p, Vec3{0, 0, 0}, index + 1, kTypeTarget);
  });
  FccBlock flyer = target;
  flyer.origin[2] = (layout.below + layout.n + layout.gap) * a;
  flyer.n[2] = layout.flyer_cells;
  const int64_t offset = target.site_count();
  for_each_fcc_site(flyer, dd.sub_lo(), dd.sub_hi(), [&](const Vec3 &p, int64_t index) {
    atoms.add_owned(p, Vec3{0, 0, 0}, offset + index + 1, kTypeFlyer);
  });
}

void create_droplet(const SceneSetup &s, int cells, const DomainDecomposition &dd, Atoms &atoms) {
  const double side = s.box.length(0);
  const Vec3 centre{0.5 * side, 0.5 * side, 0.5 * side};
  const double radius = 0.3 * side;
  auto dist2 = [&](const Vec3 &p) {
    const double dx = p[0] - centre[0], dy = p[1] - centre[1], dz = p[2] - centre[2];
    return dx * dx + dy * dy + dz * dz;
  };
  FccBlock liquid;
  liquid.a = fcc_lattice_constant(s.density);
  liquid.n[0] = liquid.n[1] = liquid.n[2] = cells;
  for_each_fcc_site(liquid, dd.sub_lo(), dd.sub_hi(), [&](const Vec3 &p, int64_t index) {
    if (dist2(p) < radius * radius) atoms.add_owned(p, Vec3{0, 0, 0}, index + 1, 1);
  });
  // Gas on a simple cubic lattice, kept one sigma clear of the drop's surface.
  const int m = std::max(1, static_cast<int>(side * std::cbrt(kGasDensity)));
  const double spacing = side / m;
  const int64_t offset = liquid.site_count();
  const double clear = (radius + 1.0) * (radius + 1.0);
  for (int k = 0; k < m; ++k) {
    for (int j = 0; j < m; ++j) {
      for (int i = 0; i < m; ++i) {
        const Vec3 p{(i + 0.5) * spacing, (j + 0.5) * spacing, (k + 0.5) * spacing};
        bool mine = true;
        for (int d = 0; d < 3; ++d) mine = mine && p[d] >= dd.sub_lo()[d] && p[d] < dd.sub_hi()[d];
        if (mine && dist2(p) > clear) {
          const int64_t index = (int64_t{k} * m + j) * m + i;
          atoms.add_owned(p, Vec3{0, 0, 0}, offset + index + 1, 2);
        }
      }
    }
  }
}

void create_random(const RunConfig &cfg, const SceneSetup &s, const DomainDecomposition &dd,
                   Atoms &atoms) {
  const int64_t n = int64_t{4} * cfg.cells * cfg.cells * cfg.cells;
  // Every rank draws every position and keeps its own: O(N) per rank, fine for the stiff tests.
  for (int64_t index = 0; index < n; ++index) {
    Vec3 p;
    bool mine = true;
    for (int d = 0; d < 3; ++d) {
      p[d] = s.box.lo[d] + uniform01(cfg.seed ^ 0x52414E44ull, index, d) * s.box.length(d);
      mine = mine && p[d] >= dd.sub_lo()[d] && p[d] < dd.sub_hi()[d];
    }
    if (mine) atoms.add_owned(p, Vec3{0, 0, 0}, index + 1, 1);
  }
}

}  // namespace

const char *scene_name(SceneKind kind) {
  switch (kind) {
    case SceneKind::kLattice:
      return "lattice";
    case SceneKind::kVoidImpact:
      return "void_impact";
    case SceneKind::kDroplet:
      return "droplet";
    case SceneKind::kRandom:
      return "random";
  }
  return "?";
}

SceneSetup define_scene(const RunConfig &cfg) {
  if (cfg.cells < 1) throw MdError("--cells must be at least 1");
  SceneSetup s;
  const SceneKind kind = cfg.random_start ? SceneKind::kRandom : cfg.scene;
  std::ostringstream what;
  switch (kind) {
    case SceneKind::kLattice:
    case SceneKind::kRandom:
    case SceneKind::kDroplet: {
      s.density = cfg.density.value_or(kLiquidDensity);
      s.temperature = cfg.temperature.value_or(kind == SceneKind::kDroplet ? 0.8 : 1.44);
      const double side = cfg.cells * fcc_lattice_constant(s.density);
      s.box.hi = {side, side, side};
      what << scene_name(kind) << ": " << cfg.cells << "^3 fcc cells at density " << s.density;
      break;
    }
    case SceneKind::kVoidImpact: {
      s.density = cfg.density.value_or(kSolidDensity);
      s.temperature = cfg.temperature.value_or(0.05);
      const double a = fcc_lattice_constant(s.density);
      const ImpactLayout layout(cfg.cells);
      s.box.hi = {cfg.cells * a, cfg.cells * a, layout.height() * a};
      s.box.periodic = {true, true, false};
      what << "void_impact: " << cfg.cells << "^2 x " << cfg.cells << " cell target (density "
           << s.density << ") with 5 voids, " << layout.flyer_cells << "-cell flyer at speed "
           << cfg.impact_speed << " along -z";
      break;
    }
  }
  apply_boundary_override(cfg.boundary, s.box);
  s.description = what.str();
  return s;
}

void create_scene_atoms(const RunConfig &cfg, const SceneSetup &setup,
                        const DomainDecomposition &dd, Atoms &atoms) {
  const SceneKind kind = cfg.random_start ? SceneKind::kRandom : cfg.scene;
  switch (kind) {
    case SceneKind::kLattice:
      create_lattice(setup, cfg.cells, dd, atoms);
      break;
    case SceneKind::kVoidImpact:
      create_void_impact(setup, cfg.cells, dd, atoms);
      break;
    case SceneKind::kDroplet:
      create_droplet(setup, cfg.cells, dd, atoms);
      break;
    case SceneKind::kRandom:
      create_random(cfg, setup, dd, atoms);
      break;
  }
}

void assign_scene_velocities(const RunConfig &cfg, const SceneSetup &setup, Atoms &atoms,
                             MPI_Comm comm) {
  create_velocities(atoms, setup.temperature, cfg.seed, comm);
  if (cfg.scene != SceneKind::kVoidImpact || cfg.random_start) return;
  for (int i = 0; i < atoms.nlocal; ++i) {
    if (atoms.type[i] == kTypeFlyer) atoms.v[i][2] -= cfg.impact_speed;
  }
}

}  // namespace mini_md
