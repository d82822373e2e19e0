// Extreme but legal particle data through the C API, with each feature: every step returns OK on
// every rank and writes its image, never a crash, hang or abort (CTest runs this at 1 and 3 ranks
// with a timeout). The data: all particles at one point, one particle, two clusters 2e15 apart, a
// plane, a line, a scalar field a few ulps wide and one of +-1e308, non-finite scalars, types at
// int32's ends, denormal coordinates, a scene 1e12 from the origin, and the scene at scales from
// 1e-9 to 1e100. Each of these found a crash, a hang or undefined behaviour once (a depth range
// too narrow for a finite scale, a legend's ticks that never ended, a colormap index of NaN, ...).
// And the default CPU image does not depend on the scene's scale: at power-of-two scales, which
// are exact in floating point, it is the unit-scale image byte for byte.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "lantern/lantern.h"
#include "tests/support/mpi_world.h"
#include "tests/support/shared_test_dir.h"

namespace lantern::testing {
namespace {

// The global lattice: 10 x 10 x 6 particles, spacing 1, radius 0.5, dealt round-robin to ranks.
constexpr int kGlobal = 600;

struct Particles {
  std::vector<double> x, radius, scalar;
  std::vector<int32_t> type;
};

// Particle g of the global set before a dataset changes it.
void lattice_particle(int g, double *x, double *radius, double *scalar, int32_t *type) {
  x[0] = g % 10, x[1] = (g / 10) % 10, x[2] = g / 100;
  *radius = 0.5, *scalar = g % 7, *type = g % 3;
}

struct Dataset {
  const char *name;
  // Changes particle g in place; returns false to leave it out (then no rank has it).
  std::function<bool(int g, double *x, double *radius, double *scalar, int32_t *type)> edit;
};

std::vector<Dataset> datasets() {
  const auto scaled = [](double k) {
    return [k](int, double *x, double *r, double *, int32_t *) {
      x[0] *= k, x[1] *= k, x[2] *= k, *r *= k;
      return true;
    };
  };
  const double inf = std::numeric_limits<double>::infinity();
  return {
      {"one_point",
       [](int, double *x, double *, double *, int32_t *) {
         x[0] = 1, x[1] = 2, x[2] = 3;
         return true;
       }},
      {"one_particle", [](int g, double *, double *, double *, int32_t *) { return g == 0; }},
      {"far_apart",
       [](int g, double *x, double *, double *, int32_t *) {
         x[0] += g % 2 ? 1e15 : -1e15;
         return true;
       }},
      {"plane",
       [](int, double *x, double *, double *, int32_t *) {
         x[2] = 0;
         return true;
       }},
      {"line",
       [](int g, double *x, double *, double *, int32_t *) {
         x[0] = g, x[1] = 0, x[2] = 0;
         return true;
       }},
      {"scalar_ulps_wide",
       [](int g, double *, double *, double *s, int32_t *) {
         *s = 1.0 + (g % 2) * std::ldexp(1.0, -52);
         return true;
       }},
      {"scalar_1e308",
       [](int g, double *, double *, double *s, int32_t *) {
         *s = g % 2 ? 1e308 : -1e308;
         return true;
       }},
      {"scalar_non_finite",
       [inf](int g, double *, double *, double *s, int32_t *) {
         *s = g % 3 == 0 ? std::nan("") : g % 3 == 1 ? inf : 1.0;
         return true;
       }},
      {"types_at_int32_ends",
       [](int g, double *, double *, double *, int32_t *t) {
         *t = g % 2 ? std::numeric_limits<int32_t>::min() : std::numeric_limits<int32_t>::max();
         return true;
       }},
      {"denormal", scaled(1e-310)},
      {"offset_1e12",
       [](int, double *x, double *, double *, int32_t *) {
         x[0] += 1e12, x[1] += 1e12;
         return true;
       }},
      {"scale_1e-9", scaled(1e-9)},
      {"scale_1e20", scaled(1e20)},
      {"scale_1e100", scaled(1e100)},
  };
}

// The lattice unchanged.
Dataset unit_lattice() {
  return {"unit", [](int, double *, double *, double *, int32_t *) { return true; }};
}

// This rank's share of a dataset: particles g with g % ranks == rank.
Particles share_of(const Dataset &d) {
  Particles p;
  for (int g = 0; g < kGlobal; ++g) {
    double x[3], radius, scalar;
    int32_t type;
    lattice_particle(g, x, &radius, &scalar, &type);
    if (!d.edit(g, x, &radius, &scalar, &type) || g % world_size() != world_rank()) continue;
    p.x.insert(p.x.end(), x, x + 3);
    p.radius.push_back(radius), p.scalar.push_back(scalar), p.type.push_back(type);
  }
  return p;
}

lantern_particles description(const Particles &p) {
  lantern_particles d{};
  d.count = int64_t(p.radius.size());
  d.position = {p.x.data(), LANTERN_FLOAT64, 0};
  d.radius = {p.radius.data(), LANTERN_FLOAT64, 0};
  d.scalar = {p.scalar.data(), LANTERN_FLOAT64, 0};
  d.type = {p.type.data(), LANTERN_INT32, 0};
  return d;
}

// Scene keys beyond the common ones (radius: per_particle, 64 x 48, a PNG per step).
const char *const kFeatures[] = {
    "",
    "    color: {by: scalar}\n    box: {}\n",
    "    ambient_occlusion: {method: object}\n",
    "    ambient_occlusion: {method: screen}\n    outline: {}\n    depth_cue: {}\n",
    "    style: density\n",
    "    lod: {fraction: 0.25}\n    culling: {occlusion: probabilistic}\n",
    "    samples: 4\n    color: {by: type}\n",
    "    cut_planes: [{normal: [1, 0, 0], offset: 0.5}]\n",
    "    camera: {projection: perspective, position: [1, 2, 3], look_at: [0, 0, 0]}\n",
    "    opacity: [0.5, 0.5, 0.5]\n    color: {by: type}\n",
    "    camera: {projection: orthographic, elevation: 90}\n",
    "    camera: {projection: perspective, elevation: -90, zoom: 100}\n",
    "    lod: {min_pixels: 4, point_path: true}\n",
    "    culling: {occlusion: hzb}\n    renderer: cpu\n",
    "    lod: {fraction: 0.3, select: nearest}\n",
};

std::string config(const std::filesystem::path &dir, const std::string &name,
                   const std::string &extra) {
  return "scenes:\n  - name: " + name +
         "\n    width: 64\n    height: 48\n    radius: per_particle\n    output: {pattern: '" +
         (dir / "{scene}_{step:04d}.png").string() + "'}\n" + extra;
}

// Every rank's status equal to `expected`.
bool on_every_rank(lantern_status status, lantern_status expected) {
  int ok = status == expected ? 1 : 0, all = 0;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return all == 1;
}

struct ContextCloser {
  void operator()(lantern_context *c) const { lantern_close(c); }
};
using Context = std::unique_ptr<lantern_context, ContextCloser>;

// Opens `text`, publishes p and renders steps 0 and 1; true when every call was OK everywhere.
bool render_two_steps(const std::string &text, const Particles &p, std::string *error) {
  lantern_context *raw = nullptr;
  const lantern_status opened = lantern_open(text.c_str(), LANTERN_COMM_WORLD, &raw);
  const Context ctx(raw);
  const lantern_particles d = description(p);
  lantern_status s = opened;
  if (s == LANTERN_OK) s = lantern_publish(ctx.get(), &d);
  for (int step = 0; step < 2 && s == LANTERN_OK; ++step) s = lantern_execute(ctx.get(), step, 0.0);
  *error = s == LANTERN_OK ? "" : lantern_error_message(ctx.get());
  return on_every_rank(s, LANTERN_OK);
}

std::string file_bytes(const std::filesystem::path &path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// OpenGL's scenes, where this build has OpenGL: the nine-spheres rule draws through it.
const char *const kGlFeatures[] = {
    "    renderer: opengl\n",
    "    culling: {occlusion: nine_spheres}\n    renderer: opengl\n",
};
// Overlay text, where this build has it (FreeType and fontconfig).
const char *const kTextFeatures[] = {
    "    color: {by: scalar}\n    legend: {title: e}\n    labels: [{text: 'step {step}'}]\n"
    "    axes: {}\n",
};

// Whether a unit lattice renders with `extra` (a feature of an optional dependency); says so
// where it does not.
bool built_with(const std::filesystem::path &dir, const std::string &extra) {
  const Dataset unit = unit_lattice();
  std::string error;
  if (render_two_steps(config(dir, "probe", extra), share_of(unit), &error)) return true;
  if (world_rank() == 0) std::printf("left out (%s): %s\n", error.c_str(), extra.c_str());
  return false;
}

TEST(ExtremeInputs, EveryFeatureRendersEveryDatasetOnEveryRank) {
  const SharedDir dir("lantern_extreme_");
  std::vector<std::string> features(std::begin(kFeatures), std::end(kFeatures));
  if (built_with(dir.path(), kGlFeatures[0]))
    features.insert(features.end(), std::begin(kGlFeatures), std::end(kGlFeatures));
  if (built_with(dir.path(), kTextFeatures[0]))
    features.insert(features.end(), std::begin(kTextFeatures), std::end(kTextFeatures));
  std::string error;
  for (const Dataset &d : datasets()) {
    const Particles p = share_of(d);
    for (size_t f = 0; f < features.size(); ++f) {
      const std::string name = std::string(d.name) + "_f" + std::to_string(f);
      EXPECT_TRUE(render_two_steps(config(dir.path(), name, features[f]), p, &error))
          << name << ": " << error << "\n"
          << features[f];
      if (world_rank() == 0)
        EXPECT_TRUE(std::filesystem::exists(dir.path() / (name + "_0001.png"))) << name;
    }
  }
}

// Steps anywhere in int64, in any order, with the particles moving between them (the bricks'
// refit extrapolates over step differences, which overflowed from INT64_MIN to 0), and with
// object AO's packed deposit reading positions at an address that is not a multiple of 8 (the
// API allows any): OK on every rank, an image each.
TEST(ExtremeInputs, StepsAtInt64sEndsAndUnalignedPositions) {
  const SharedDir dir("lantern_extreme_");
  const Dataset unit = unit_lattice();
  const Particles p = share_of(unit);
  std::vector<char> bytes(p.x.size() * sizeof(double) + 1);
  const std::string text =
      "scenes:\n  - name: s\n    width: 64\n    height: 48\n    radius: 0.5\n"
      "    ambient_occlusion: {method: object}\n    output: {pattern: '" +
      (dir.path() / "s_{step}.png").string() + "'}\n";
  lantern_context *raw = nullptr;
  ASSERT_TRUE(on_every_rank(lantern_open(text.c_str(), LANTERN_COMM_WORLD, &raw), LANTERN_OK));
  const Context ctx(raw);
  const int64_t lowest = std::numeric_limits<int64_t>::min();
  const int64_t highest = std::numeric_limits<int64_t>::max();
  int frame = 0;
  for (const int64_t step : {lowest, lowest + 1, int64_t(0), int64_t(1), highest - 1, highest}) {
    // The lattice shifted a little further each step, at byte offset 1.
    std::vector<double> moved = p.x;
    for (double &v : moved) v += 0.01 * frame;
    std::memcpy(bytes.data() + 1, moved.data(), moved.size() * sizeof(double));
    lantern_particles d = description(p);
    d.position = {bytes.data() + 1, LANTERN_FLOAT64, 0};
    ASSERT_TRUE(on_every_rank(lantern_publish(ctx.get(), &d), LANTERN_OK));
    EXPECT_TRUE(on_every_rank(lantern_execute(ctx.get(), step, 0.0), LANTERN_OK))
        << step << ": " << lantern_error_message(ctx.get());
    if (world_rank() == 0)
      EXPECT_TRUE(std::filesystem::exists(dir.path() / ("s_" + std::to_string(step) + ".png")))
          << step;
    ++frame;
  }
}

// Bonded chains (every 10 atoms along x, joined across the periodic x and y faces) in boxes
// with extreme tilts - far beyond the box, tiny, of opposite signs - and lengths: every step
// returns OK on every rank with its image (bonds, the box overlay, culling), never a crash.
TEST(ExtremeInputs, TriclinicBoxesWithExtremeTiltsRenderTheirBonds) {
  const SharedDir dir("lantern_extreme_");
  // Rank 0 publishes every particle of the lattice (its bonds need no ghosts); the others none.
  Particles p;
  if (world_rank() == 0)
    for (int g = 0; g < kGlobal; ++g) {
      double x[3], radius, scalar;
      int32_t type;
      lattice_particle(g, x, &radius, &scalar, &type);
      p.x.insert(p.x.end(), x, x + 3);
      p.radius.push_back(radius), p.scalar.push_back(scalar), p.type.push_back(type);
    }
  std::vector<int64_t> first, second;
  if (world_rank() == 0)
    for (int g = 0; g < kGlobal; ++g) {
      first.push_back(g), second.push_back(g - g % 10 + (g + 1) % 10);  // x rows, wrapping
      first.push_back(g), second.push_back((g + 10) % kGlobal);         // along y, and on
    }
  const std::string text =
      "scenes:\n  - name: s\n    width: 64\n    height: 48\n    radius: 0.3\n"
      "    bonds: {radius: 0.1}\n    box: {}\n    culling: {occlusion: hzb}\n"
      "    output: {pattern: '" +
      (dir.path() / "s_{step}.png").string() + "'}\n";
  lantern_context *raw = nullptr;
  ASSERT_TRUE(on_every_rank(lantern_open(text.c_str(), LANTERN_COMM_WORLD, &raw), LANTERN_OK));
  const Context ctx(raw);
  const double big = 1e300, tiny = 1e-310;
  const double tilts[][3] = {
      {big, 0, 0}, {0, -big, big}, {tiny, -tiny, tiny}, {-5, 7, -3}, {0, 0, 0}};
  const double lows[][3] = {{0, 0, 0}, {-1e300, -1e300, -1e300}};
  const double highs[][3] = {{10, 10, 6}, {1e300, 1e300, 1e300}};
  const int periodic[3] = {1, 1, 1};
  int step = 0;
  for (int box = 0; box < 2; ++box)
    for (const auto &tilt : tilts) {
      lantern_particles d = description(p);
      lantern_bonds b{};
      b.count = int64_t(first.size());
      b.first = {first.data(), LANTERN_INT64, 0};
      b.second = {second.data(), LANTERN_INT64, 0};
      ASSERT_TRUE(on_every_rank(lantern_publish(ctx.get(), &d), LANTERN_OK));
      ASSERT_TRUE(on_every_rank(lantern_publish_bonds(ctx.get(), &b), LANTERN_OK))
          << lantern_error_message(ctx.get());
      // Edges of 10 and of 2e300 (the largest lengths that stay finite, near enough), any tilt.
      ASSERT_TRUE(on_every_rank(
          lantern_set_triclinic_box(ctx.get(), lows[box], highs[box], tilt, periodic), LANTERN_OK))
          << lantern_error_message(ctx.get());
      EXPECT_TRUE(on_every_rank(lantern_execute(ctx.get(), step, 0.0), LANTERN_OK))
          << "box " << box << ", tilt " << tilt[0] << " " << tilt[1] << " " << tilt[2] << ": "
          << lantern_error_message(ctx.get());
      if (world_rank() == 0)
        EXPECT_TRUE(std::filesystem::exists(dir.path() / ("s_" + std::to_string(step) + ".png")));
      ++step;
    }
}

TEST(ExtremeInputs, TheDefaultImageIsTheSameAtEveryPowerOfTwoScale) {
  const SharedDir dir("lantern_extreme_");
  const Dataset unit = unit_lattice();
  // Colours by scalar (with its legend where the build has text), super-sampled, object-space
  // AO: scale-free stages too.
  const std::string colours = "    color: {by: scalar}\n";
  const std::string legend = colours + "    legend: {}\n";
  const std::string extra = "    samples: 4\n" +
                            (built_with(dir.path(), legend) ? legend : colours) +
                            "    ambient_occlusion: {method: object}\n";
  std::string error;
  ASSERT_TRUE(render_two_steps(config(dir.path(), "unit", extra), share_of(unit), &error)) << error;
  const std::string reference = file_bytes(dir.path() / "unit_0001.png");
  for (const int e : {-30, -10, 20, 40, 100, 400}) {
    const double k = std::ldexp(1.0, e);
    const Dataset d{"scaled", [k](int, double *x, double *r, double *, int32_t *) {
                      x[0] *= k, x[1] *= k, x[2] *= k, *r *= k;
                      return true;
                    }};
    const std::string name = "scale_" + std::to_string(e + 1000);
    ASSERT_TRUE(render_two_steps(config(dir.path(), name, extra), share_of(d), &error))
        << "2^" << e << ": " << error;
    if (world_rank() == 0)
      EXPECT_TRUE(file_bytes(dir.path() / (name + "_0001.png")) == reference) << "2^" << e;
  }
}

}  // namespace
}  // namespace lantern::testing
