// Bonds drawn as cylinders (core/bricks/brick_bonds.h, core/culling/bond_selection.h, the CPU
// raster's draw_bond and OpenGL's bond impostor), as the pipeline draws a rank's scene: analytic
// silhouettes and depths in both renderers, flat end discs, by_atom split at the midpoint, the
// minimum image on both sides of half the box, cutting planes taking each half with its atom,
// the two renderers agreeing, and the exact culling modes bit-identical to drawing everything.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/bricks/brick_bonds.h"
#include "core/camera/camera.h"
#include "core/pipeline/rank_draw.h"
#include "core/pipeline/scene_settings.h"
#include "core/render/centred_cylinder_cast.h"
#include "core/render/cpu_sphere_raster.h"
#include "core/render/cylinder_cast.h"
#include "core/render/gl/gl_session.h"
#include "core/view/cylinder_bounds.h"
#include "tests/support/bonded_molecules.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

// The bond list of `s` (pairs of int64 atom indices, 16 bytes apart), borrowed.
BondDescription bond_pairs(const testing::BondedSystem &s) {
  BondDescription b;
  b.count = int64_t(s.bond_count());
  b.first = {s.bonds.data(), DataType::kInt64, 16};
  b.second = {s.bonds.data() + 1, DataType::kInt64, 16};
  return b;
}

using testing::BondedSystem;

// The half-bonds a refit kept are, bit for bit, those a build of the same step gives.
void expect_same_bits(const BrickBonds &kept, const BrickBonds &built) {
  ASSERT_EQ(kept.halves.size(), built.halves.size());
  EXPECT_EQ(0, std::memcmp(kept.halves.data(), built.halves.data(),
                           built.halves.size() * sizeof(HalfBond)));
  EXPECT_EQ(kept.first, built.first);
  ASSERT_EQ(kept.lo.size(), built.lo.size());
  ASSERT_EQ(kept.hi.size(), built.hi.size());
  ASSERT_EQ(kept.reach.size(), built.reach.size());
  EXPECT_EQ(0, std::memcmp(kept.lo.data(), built.lo.data(), built.lo.size() * sizeof(glm::dvec3)));
  EXPECT_EQ(0, std::memcmp(kept.hi.data(), built.hi.data(), built.hi.size() * sizeof(glm::dvec3)));
  EXPECT_EQ(
      0, std::memcmp(kept.reach.data(), built.reach.data(), built.reach.size() * sizeof(double)));
}

// A bonded system (owned here) lent to the pipeline's structures as a rank holds it.
struct Lent {
  const BondedSystem s;
  ParticleArrays particles;
  BondArrays bonds;
  BrickSet bricks;
  BrickBonds halves;
  std::optional<PeriodicBox> box;

  // `tilt`: a triclinic box's {xy, xz, yz} (PeriodicBox::tilt), where periodic.
  Lent(BondedSystem system, bool periodic, BondListing listing = BondListing::kListedOnce,
       std::array<double, 3> tilt = {0, 0, 0})
      : s(std::move(system)) {
    ParticleDescription p;
    p.count = int64_t(s.atoms());
    p.position = {s.xyz.data(), DataType::kFloat64, 0};
    p.type = {s.type.data(), DataType::kInt32, 0};
    p.id = {s.id.data(), DataType::kInt64, 0};
    EXPECT_OK(ParticleArrays::validate(p, &particles));
    BondDescription b = bond_pairs(s);
    b.type = {s.bond_type.data(), DataType::kInt32, 0};
    b.listing = listing;
    EXPECT_OK(BondArrays::validate(b, particles, &bonds));
    if (periodic) {
      PeriodicBox pb;
      pb.length = {s.box, s.box, s.box};
      pb.periodic = {true, true, true};
      pb.tilt = tilt;
      box = pb;
    }
    bricks = build_bricks(particles, BrickOptions{});
    build_brick_bonds(particles, bonds, bricks, box ? &*box : nullptr, &halves);
    EXPECT_OK(halves.first_error);
  }
  Lent(const Lent &) = delete;
  Lent &operator=(const Lent &) = delete;
};

class BondRender : public ::testing::Test {
 protected:
  void SetUp() override {
    if (gl_backend_built(GlBackend::kEgl) || gl_backend_built(GlBackend::kOsmesa)) {
      EXPECT_OK(acquire_renderer(GlBackend::kAuto, &session_, &renderer_));
    }
  }
  // ExactCullingIsBitIdenticalToDrawingEverything in an orthogonal or a triclinic box.
  void expect_bonds_cull_exactly(bool tilted);

  std::vector<RendererChoice> renderers() const {
    std::vector<RendererChoice> r = {RendererChoice::kCpu};
    if (renderer_) r.push_back(RendererChoice::kOpenGl);
    return r;
  }

  // The scene drawn on one rank by `choice` (OpenGL needs the renderer), counts in *out.
  Frame draw(const Lent &m, SceneConfig scene, const Camera &cam, RendererChoice choice,
             RankDraw *out = nullptr) {
    scene.renderer = choice;
    RankScene rank(m.particles, m.bricks, cam, scene);
    rank.bonds = &m.bonds;
    rank.bond_halves = &m.halves;
    rank.box = m.box ? &*m.box : nullptr;
    rank.renderer = choice == RendererChoice::kOpenGl ? renderer_ : nullptr;
    RankDrawScratch scratch;
    Frame frame;
    RankDraw drawn;
    EXPECT_OK(draw_scene_on_rank(rank, &scratch, &frame, &drawn));
    EXPECT_EQ(drawn.renderer, choice == RendererChoice::kOpenGl ? "opengl" : "cpu");
    if (out) *out = drawn;
    return frame;
  }

  // Scene s drawn by `choice` twice - brute force (no frustum, no occlusion culling) and with
  // hzb - expecting the same bytes; the counts of each in *all and *fast.
  void expect_hzb_exact(const Lent &m, const SceneConfig &s, const Camera &cam,
                        RendererChoice choice, const std::string &what, RankDraw *all,
                        RankDraw *fast) {
    SceneConfig brute = s;
    brute.culling.frustum = false;
    brute.culling.occlusion = OcclusionMode::kNone;
    SceneConfig exact = s;
    exact.culling.occlusion = OcclusionMode::kHzb;
    const Frame a = draw(m, brute, cam, choice, all);
    const Frame b = draw(m, exact, cam, choice, fast);
    EXPECT_EQ(a.rgba, b.rgba) << what;
    EXPECT_EQ(a.depth, b.depth) << what;
  }

  std::shared_ptr<GlSession> session_;
  SphereRenderer *renderer_ = nullptr;
};

const char *name_of(RendererChoice r) {
  return r == RendererChoice::kOpenGl ? "opengl" : "cpu";
}

SceneConfig bond_scene(int w, int h, double atom_radius, double bond_radius) {
  SceneConfig s;
  s.width = w, s.height = h;
  s.radius = atom_radius;
  s.background = {0, 0, 0};
  s.culling.occlusion = OcclusionMode::kNone;
  s.bonds.enabled = true;
  s.bonds.radius = bond_radius;
  s.color.by = ColorBy::kType;
  s.color.palette = {{1, 0, 0}, {0, 0, 1}};
  return s;
}

// An explicit camera at `eye` looking at the origin with +y up.
Camera look_from(const SceneConfig &s, Projection projection, glm::dvec3 eye, double zoom = 1) {
  CameraConfig cfg;
  cfg.projection = projection;
  cfg.position = std::array<double, 3>{eye.x, eye.y, eye.z};
  cfg.look_at = {0, 0, 0};
  cfg.up = {0, 1, 0};
  cfg.zoom = zoom;
  Camera cam;
  EXPECT_OK(make_camera(cfg, {-3, -3, -3}, {3, 3, 3}, 0.5, s.width, s.height, &cam));
  return cam;
}

// Two atoms and the bond between them.
BondedSystem dumbbell(glm::dvec3 a, glm::dvec3 b, int32_t type_a = 0, int32_t type_b = 1) {
  BondedSystem s;
  s.xyz = {a.x, a.y, a.z, b.x, b.y, b.z};
  s.type = {type_a, type_b};
  s.id = {1, 2};
  s.bonds = {0, 1};
  s.bond_type = {0};
  return s;
}

// World x, y of pixel (x, y)'s centre for an orthographic camera on +z looking at the origin.
glm::dvec2 ortho_world(const Camera &cam, const Frame &f, int x, int y) {
  const double per_pixel = 2.0 / (cam.projection[0][0] * f.width);
  return {(x + 0.5 - f.width / 2.0) * per_pixel, (f.height / 2.0 - y - 0.5) * per_pixel};
}

bool drawn(const Frame &f, int x, int y) {
  return f.depth[f.index(x, y)] != kBackgroundDepth;
}

// A bond across the image seen side-on: the rectangle |x| <= 2, |y| <= r, every pixel at the
// depth of the cylinder's front, d - sqrt(r^2 - y^2); the tiny atoms hide inside it.
TEST_F(BondRender, SideOnSilhouetteAndDepthMatchTheAnalyticCylinder) {
  const double r = 0.5, d = 20.0;
  const Lent m(dumbbell({-2, 0, 0}, {2, 0, 0}), false);
  const SceneConfig s = bond_scene(320, 160, 0.01, r);
  const Camera cam = look_from(s, Projection::kOrthographic, {0, 0, d}, 2.5);
  for (const RendererChoice renderer : renderers()) {
    const Frame f = draw(m, s, cam, renderer);
    int wrong_coverage = 0, checked = 0;
    double worst_depth = 0.0;
    for (int y = 0; y < f.height; ++y)
      for (int x = 0; x < f.width; ++x) {
        const glm::dvec2 w = ortho_world(cam, f, x, y);
        const double edge = std::min(2.0 - std::abs(w.x), r - std::abs(w.y));
        const double px = 2.0 / (cam.projection[0][0] * f.width);
        if (std::abs(edge) < px) continue;  // within a pixel of the outline
        const bool inside = edge > 0;
        wrong_coverage += inside != drawn(f, x, y);
        if (!inside) continue;
        ++checked;
        const double expected = d - std::sqrt(r * r - w.y * w.y);
        worst_depth = std::max(
            worst_depth, std::abs(cam.window_depth_to_distance(f.depth[f.index(x, y)]) - expected));
      }
    EXPECT_GT(checked, 3000) << name_of(renderer);
    EXPECT_EQ(wrong_coverage, 0) << name_of(renderer);
    EXPECT_LT(worst_depth, 1e-3) << name_of(renderer);
  }
}

// Seen along its axis a bond is its end disc: flat (one depth), of the bond's radius, in either
// projection; facing the viewer, one color in orthographic view. (The atom at the disc's centre
// pokes through it: its few pixels are left out.)
TEST_F(BondRender, EndOnABondShowsItsFlatEndDisc) {
  const double r = 0.6;
  const Lent m(dumbbell({0, 0, -2}, {0, 0, 2}, 0, 0), false);
  const SceneConfig s = bond_scene(200, 200, 0.02, r);
  for (const Projection projection : {Projection::kOrthographic, Projection::kPerspective}) {
    const Camera cam = look_from(s, projection, {0, 0, 20}, 2.0);
    for (const RendererChoice renderer : renderers()) {
      const Frame f = draw(m, s, cam, renderer);
      int disc = 0, other_depth = 0, other_color = 0;
      const size_t reference = f.index(f.width / 2 + 10, f.height / 2);
      for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x) {
          const size_t i = f.index(x, y);
          if (f.depth[i] == kBackgroundDepth) continue;
          ++disc;
          if (std::hypot(x + 0.5 - f.width / 2.0, y + 0.5 - f.height / 2.0) < 4.0) continue;
          other_depth += std::abs(cam.window_depth_to_distance(f.depth[i]) - 18.0) > 1e-3;
          other_color += std::memcmp(&f.rgba[4 * i], &f.rgba[4 * reference], 3) != 0;
        }
      // The disc's area in pixels: radius r at distance 18 (perspective) or the box's scale.
      const double px_per_unit = projection == Projection::kOrthographic
                                     ? cam.projection[1][1] * f.height / 2.0
                                     : cam.projection[1][1] * f.height / 2.0 / 18.0;
      const double area = M_PI * r * r * px_per_unit * px_per_unit;
      EXPECT_NEAR(disc, area, 0.05 * area) << name_of(renderer);
      EXPECT_EQ(other_depth, 0) << name_of(renderer);
      if (projection == Projection::kOrthographic) {
        EXPECT_EQ(other_color, 0) << name_of(renderer);
        EXPECT_EQ(f.rgba[4 * reference], 255) << name_of(renderer);  // red, facing the light
      }
    }
  }
}

// color: by_atom splits the bond at its midpoint into the atoms' colors; by_type and solid give
// the whole bond one color.
TEST_F(BondRender, ByAtomSplitsAtTheMidpointAndTheOtherModesDoNot) {
  const Lent m(dumbbell({-2, 0, 0}, {2, 0, 0}), false);
  SceneConfig s = bond_scene(320, 160, 0.05, 0.5);
  const Camera cam = look_from(s, Projection::kOrthographic, {0, 0, 20}, 2.5);
  for (const RendererChoice renderer : renderers()) {
    s.bonds.color = BondColorBy::kAtom;
    const Frame f = draw(m, s, cam, renderer);
    int red = 0, blue = 0, wrong = 0;
    for (int x = 0; x < f.width; ++x) {
      const glm::dvec2 w = ortho_world(cam, f, x, f.height / 2);
      if (std::abs(w.x) > 1.9 || std::abs(w.x) < 0.05) continue;
      const uint8_t *c = &f.rgba[4 * f.index(x, f.height / 2)];
      const bool is_red = c[0] > c[2], is_blue = c[2] > c[0];  // plus a white highlight
      red += w.x < 0 && is_red, blue += w.x > 0 && is_blue;
      wrong += (w.x < 0 && !is_red) || (w.x > 0 && !is_blue);
    }
    EXPECT_GT(red, 50) << name_of(renderer);
    EXPECT_GT(blue, 50) << name_of(renderer);
    EXPECT_EQ(wrong, 0) << name_of(renderer);
    for (const BondColorBy by : {BondColorBy::kType, BondColorBy::kSolid}) {
      s.bonds.color = by;
      s.bonds.solid = {0, 1, 0};
      s.bonds.palette = {{1, 1, 0}};
      const Frame one = draw(m, s, cam, renderer);
      const uint8_t *left = &one.rgba[4 * one.index(one.width / 2 - 40, one.height / 2)];
      const uint8_t *right = &one.rgba[4 * one.index(one.width / 2 + 40, one.height / 2)];
      EXPECT_EQ(std::memcmp(left, right, 4), 0) << name_of(renderer);
      EXPECT_EQ(left[1], 255) << name_of(renderer);  // green or yellow, lit head-on
      if (by == BondColorBy::kType)
        EXPECT_EQ(left[0], 255) << name_of(renderer);  // yellow
      else
        EXPECT_LT(left[0], 100) << name_of(renderer);  // green, with the white highlight
    }
  }
}

// Periodic boxes (edge 10): a bond just under half the box is drawn whole through the inside;
// one just over it is two half-bonds, each from its own atom out through its own face to the
// minimum image's midpoint - nothing in between. Without the box, the long bond spans the box.
TEST_F(BondRender, BondsAreDrawnInTheMinimumImageOnBothSidesOfHalfTheBox) {
  BondedSystem s;
  // Row y = 2: 4.9 apart (drawn whole). Row y = -2: 8.8 apart, so the minimum image is 1.2
  // across x = 0: half-bonds from 0.8 down to 0.2 and from 9.6 up to 10.2.
  s.xyz = {0.5, 2, 0, 5.4, 2, 0, 0.8, -2, 0, 9.6, -2, 0};
  s.type = {0, 0, 0, 0};
  s.id = {1, 2, 3, 4};
  s.bonds = {0, 1, 2, 3};
  s.bond_type = {0, 0};
  s.box = 10.0;
  SceneConfig scene = bond_scene(400, 240, 0.05, 0.3);
  CameraConfig cfg;
  cfg.projection = Projection::kOrthographic;
  cfg.position = std::array<double, 3>{5, 0, 30};
  cfg.look_at = {5, 0, 0};
  cfg.up = {0, 1, 0};
  Camera cam;
  ASSERT_OK(make_camera(cfg, {-1, -4, -1}, {11, 4, 1}, 0.5, scene.width, scene.height, &cam));
  const auto pixel_at = [&](const Frame &f, double wx, double wy) {
    const double per_unit = cam.projection[0][0] * f.width / 2.0;
    return drawn(f, int((wx - 5.0) * per_unit + f.width / 2.0),
                 int(f.height / 2.0 - wy * per_unit));
  };
  for (const bool periodic : {true, false}) {
    const Lent m(s, periodic);
    for (const RendererChoice renderer : renderers()) {
      const Frame f = draw(m, scene, cam, renderer);
      const std::string what = std::string(name_of(renderer)) + (periodic ? " periodic" : "");
      for (const double x : {1.0, 3.0, 5.0}) EXPECT_TRUE(pixel_at(f, x, 2)) << what << " x=" << x;
      EXPECT_FALSE(pixel_at(f, 5.9, 2)) << what;
      // Row y = -2, from left to right: out of the low face, the stub's end, the stub, the gap
      // (or the whole bond), the other stub, out of the high face, beyond its end.
      const double xs[] = {0.1, 0.4, 1.5, 5.0, 9.8, 10.1, 10.4};
      const bool split[] = {false, true, false, false, true, true, false};
      const bool whole[] = {false, false, true, true, false, false, false};
      for (int k = 0; k < 7; ++k)
        EXPECT_EQ(pixel_at(f, xs[k], -2), periodic ? split[k] : whole[k]) << what << " x=" << xs[k];
    }
  }
}

// A triclinic box (edge 10, xy = 4): a bond across the tilted y face. Its atoms are stored at
// (5, 0.5) and (9.6, 9.5), whose closest image through b = (4, 10, 0) is 0.6 right of and 1 below
// the first: half-bonds from each atom out through its own face, a short stub each. The
// orthogonal box of the same lengths takes the image straight below, (9.6, -0.5): its stubs run
// 2.3 across instead.
TEST_F(BondRender, BondsAcrossATiltedFaceAreDrawnInTheTriclinicMinimumImage) {
  BondedSystem s;
  s.xyz = {5, 0.5, 0, 9.6, 9.5, 0};
  s.type = {0, 0};
  s.id = {1, 2};
  s.bonds = {0, 1};
  s.bond_type = {0};
  s.box = 10.0;
  SceneConfig scene = bond_scene(400, 400, 0.05, 0.15);
  CameraConfig cfg;
  cfg.projection = Projection::kOrthographic;
  cfg.position = std::array<double, 3>{7, 5, 30};
  cfg.look_at = {7, 5, 0};
  cfg.up = {0, 1, 0};
  Camera cam;
  ASSERT_OK(make_camera(cfg, {0, -1, -1}, {14, 11, 1}, 0.5, scene.width, scene.height, &cam));
  const auto pixel_at = [&](const Frame &f, double wx, double wy) {
    const double per_unit = cam.projection[0][0] * f.width / 2.0;
    return drawn(f, int((wx - 7.0) * per_unit + f.width / 2.0),
                 int(f.height / 2.0 - (wy - 5.0) * per_unit));
  };
  for (const bool tilted : {true, false}) {
    const Lent m(s, true, BondListing::kListedOnce,
                 tilted ? std::array<double, 3>{4, 0, 0} : std::array<double, 3>{0, 0, 0});
    for (const RendererChoice renderer : renderers()) {
      const Frame f = draw(m, scene, cam, renderer);
      const std::string what =
          std::string(name_of(renderer)) + (tilted ? " tilted" : " orthogonal");
      // The first atom's stub: to (5.3, 0) tilted, to (7.3, 0) orthogonal (points on each, 0.2
      // or more from the other, whose radius is 0.15).
      EXPECT_EQ(pixel_at(f, 5.15, 0.25), tilted) << what;
      EXPECT_EQ(pixel_at(f, 6.0, 0.283), !tilted) << what;
      // The second atom's stub: from (9.6, 9.5) to (9.3, 10) tilted, to (7.3, 10) orthogonal.
      EXPECT_EQ(pixel_at(f, 9.45, 9.75), tilted) << what;
      EXPECT_EQ(pixel_at(f, 8.6, 9.717), !tilted) << what;
    }
  }
}

// A cutting plane through a bond (x > 0 dropped): the atom at x = -2 keeps its half, up to the
// midpoint; the other half went with its atom.
TEST_F(BondRender, ACutPlaneTakesEachHalfWithItsAtom) {
  const Lent m(dumbbell({-2, 0, 0}, {2, 0, 0}), false);
  SceneConfig s = bond_scene(320, 160, 0.05, 0.5);
  CutPlane cut;
  cut.normal = {1, 0, 0};
  cut.offset = 0.0;
  s.cuts = {cut};
  const Camera cam = look_from(s, Projection::kOrthographic, {0, 0, 20}, 2.5);
  for (const RendererChoice renderer : renderers()) {
    RankDraw out;
    const Frame f = draw(m, s, cam, renderer, &out);
    int left = 0, right = 0;
    for (int x = 0; x < f.width; ++x) {
      const glm::dvec2 w = ortho_world(cam, f, x, f.height / 2);
      if (std::abs(w.x) < 0.05) continue;
      (w.x < 0 ? left : right) += drawn(f, x, f.height / 2);
    }
    EXPECT_GT(left, 50) << name_of(renderer);
    EXPECT_EQ(right, 0) << name_of(renderer);
    EXPECT_EQ(out.cull.bonds.cut_culled, 1) << name_of(renderer);
    EXPECT_EQ(out.cull.bonds.drawn, 1) << name_of(renderer);
  }
}

// A polymer melt seen from outside and from a camera inside it, both projections: the CPU
// raster (double) and OpenGL (float) agree as closely as they do for spheres alone.
TEST_F(BondRender, CpuRasterAndOpenGlAgree) {
  if (!renderer_) GTEST_SKIP() << "no OpenGL in this build";
  const BondedSystem melt = testing::polymer_melt(40, 40, 14.0);
  const Lent m(melt, true);
  int64_t drawn_pixels = 0, coverage = 0, off_by_more = 0;
  int max_channel = 0;
  for (int view = 0; view < 4; ++view) {
    SceneConfig s = bond_scene(300, 220, 0.35, 0.15);
    s.color.by = ColorBy::kType;
    s.color.palette.clear();
    s.camera.projection = view % 2 ? Projection::kOrthographic : Projection::kPerspective;
    s.camera.azimuth = 20.0 + 70.0 * view;
    s.camera.zoom = view < 2 ? 1.0 : 3.0;  // the later views see part of the box up close
    Camera cam;
    ASSERT_OK(make_camera(s.camera, {0, 0, 0}, {14, 14, 14}, 0.35, s.width, s.height, &cam));
    const Frame cpu = draw(m, s, cam, RendererChoice::kCpu);
    const Frame gl = draw(m, s, cam, RendererChoice::kOpenGl);
    for (size_t i = 0; i < gl.pixel_count(); ++i) {
      const bool a = gl.depth[i] != kBackgroundDepth, b = cpu.depth[i] != kBackgroundDepth;
      drawn_pixels += b;
      if (a != b) {
        ++coverage;
        continue;
      }
      int worst = 0;
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(int(gl.rgba[4 * i + k]) - int(cpu.rgba[4 * i + k])));
      off_by_more += worst > 1;
      max_channel = std::max(max_channel, worst);
    }
  }
  std::printf(
      "bonds, opengl vs cpu: %lld of %lld drawn pixels differ in coverage, %lld by more "
      "than one level (max %d)\n",
      (long long)coverage, (long long)drawn_pixels, (long long)off_by_more, max_channel);
  EXPECT_GT(drawn_pixels, 50000);
  EXPECT_LE(coverage, drawn_pixels / 2000);     // silhouettes within rounding of a pixel centre
  EXPECT_LE(off_by_more, drawn_pixels / 2000);  // where bond and sphere surfaces cross
}

// The exact modes with bonds: frustum culling and hzb (CPU raster, OpenGL) give the bytes of
// drawing every sphere and bond, from outside and from a camera up close, and do cull.
// Every culling mode against drawing everything, in an orthogonal box and a triclinic one (the
// melt sheared into it: its bonds across the tilted faces take the triclinic minimum image).
TEST_F(BondRender, ExactCullingIsBitIdenticalToDrawingEverything) {
  for (const bool tilted : {false, true}) expect_bonds_cull_exactly(tilted);
}

void BondRender::expect_bonds_cull_exactly(bool tilted) {
  BondedSystem melt = testing::polymer_melt(60, 60, 16.0);
  const std::array<double, 3> tilt =
      tilted ? std::array<double, 3>{5.0, -3.0, 2.5} : std::array<double, 3>{0, 0, 0};
  for (size_t i = 0; i < melt.atoms(); ++i) {  // fractional coordinates into the tilted box
    double *x = &melt.xyz[3 * i];
    x[0] += tilt[0] * x[1] / 16.0 + tilt[1] * x[2] / 16.0, x[1] += tilt[2] * x[2] / 16.0;
  }
  const Lent m(melt, true, BondListing::kListedOnce, tilt);
  int64_t culled = 0;
  for (int view = 0; view < 3; ++view) {
    SceneConfig s = bond_scene(320, 240, 0.45, 0.2);
    s.camera.azimuth = 35.0 + 100.0 * view;
    s.camera.zoom = view == 2 ? 4.0 : 1.0;
    if (view == 1) {
      CutPlane cut;
      cut.normal = {0.3, 1, 0.2};
      cut.offset = 9.0;
      s.cuts = {cut};
    }
    Camera cam;
    ASSERT_OK(make_camera(s.camera, {0, 0, 0}, {16, 16, 16}, 0.45, s.width, s.height, &cam));
    for (const RendererChoice renderer : renderers()) {
      const std::string what = std::string(name_of(renderer)) + " view " + std::to_string(view) +
                               (tilted ? " tilted" : "");
      RankDraw all, fast;
      expect_hzb_exact(m, s, cam, renderer, what, &all, &fast);
      const BondCounts &c = fast.cull.bonds;
      EXPECT_EQ(c.halves, int64_t(2 * melt.bond_count())) << what;
      EXPECT_EQ(c.halves,
                c.drawn + c.frustum_culled + c.cut_culled + c.lod_dropped + c.occlusion_culled)
          << what;
      // Drawing everything leaves out only halves cut away or wholly off the image.
      EXPECT_EQ(all.cull.bonds.frustum_culled, 0) << what;
      EXPECT_EQ(all.cull.bonds.drawn + all.cull.bonds.cut_culled + all.cull.bonds.occlusion_culled,
                c.halves)
          << what;
      culled += c.occlusion_culled + c.frustum_culled;
      std::printf("%s: %lld of %lld half-bonds drawn (%lld hidden, %lld outside, %lld cut)\n",
                  what.c_str(), (long long)c.drawn, (long long)c.halves,
                  (long long)c.occlusion_culled, (long long)c.frustum_culled,
                  (long long)c.cut_culled);
    }
  }
  EXPECT_GT(culled, int64_t(melt.bond_count()));  // most hidden from outside, more up close
}

// A dense network seen from outside, listed once and by both ranks' rule: culling judges the
// halves of one atom together (the sphere round the atom that holds them) and draws each
// brick's bonds after its atoms, and the image stays that of drawing everything.
TEST_F(BondRender, AtomRunsCullExactlyInADenseNetwork) {
  for (const BondListing listing : {BondListing::kListedOnce, BondListing::kListedByBoth}) {
    const BondedSystem net = testing::network(7, 3, 4.0, 0.1);
    const Lent m(net, false, listing);
    SceneConfig s = bond_scene(256, 192, 0.5, 0.25);
    s.camera.azimuth = 30.0;
    Camera cam;
    ASSERT_OK(make_camera(s.camera, {0, 0, 0}, {28, 28, 28}, 0.5, s.width, s.height, &cam));
    for (const RendererChoice renderer : renderers()) {
      const std::string what =
          std::string(name_of(renderer)) + " listing " + std::to_string(int(listing));
      RankDraw all, fast;
      expect_hzb_exact(m, s, cam, renderer, what, &all, &fast);
      const BondCounts &c = fast.cull.bonds;
      EXPECT_EQ(c.halves, int64_t(2 * net.bond_count())) << what;
      // A good part of the block is hidden behind its near faces.
      EXPECT_GT(c.occlusion_culled, c.halves / 10) << what;
      EXPECT_LT(c.drawn, all.cull.bonds.drawn) << what;
    }
  }
}

// Level of detail: the bonds of thinned bricks are left out, and counted so.
TEST_F(BondRender, LevelOfDetailLeavesOutTheBondsOfThinnedBricks) {
  const Lent m(testing::polymer_melt(60, 60, 16.0), true);
  SceneConfig s = bond_scene(200, 150, 0.45, 0.2);
  s.lod.fraction = 0.25;
  Camera cam;
  ASSERT_OK(make_camera(s.camera, {0, 0, 0}, {16, 16, 16}, 0.45, s.width, s.height, &cam));
  RankDraw out;
  draw(m, s, cam, RendererChoice::kCpu, &out);
  EXPECT_EQ(out.cull.bonds.lod_dropped, out.cull.bonds.halves);
}

// A 97 x 64 view, perspective or orthographic, near 0.1 and far 200, for the per-pixel tests.
ViewGeometry small_view(bool ortho) {
  ViewGeometry g;
  g.orthographic = ortho;
  g.width = 97, g.height = 64;
  g.near_plane = 0.1, g.far_plane = 200.0;
  g.sx = ortho ? 0.08 : 1.3, g.sy = ortho ? 0.12 : 1.95;
  g.p22 = ortho ? -2.0 / (g.far_plane - g.near_plane)
                : -(g.far_plane + g.near_plane) / (g.far_plane - g.near_plane);
  g.p32 = ortho ? -(g.far_plane + g.near_plane) / (g.far_plane - g.near_plane)
                : -2.0 * g.far_plane * g.near_plane / (g.far_plane - g.near_plane);
  g.eps = 1e-5;
  return g;
}

// cylinder_rect takes a box's rectangle from its bounds (ViewGeometry::box_rect(lo, hi)): the
// very rectangle of its 8 corners, for boxes far and near, straddling the eye's axes, reaching
// behind half the near plane, flat, and with NaN or infinite bounds.
TEST(CylinderRows, BoxRectOfBoundsIsThatOfItsCorners) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), pos(0.0, 1.0);
  const double nan = std::nan(""), inf = INFINITY;
  int64_t boxes = 0, whole = 0;
  for (const bool ortho : {false, true}) {
    const ViewGeometry g = small_view(ortho);
    for (int trial = 0; trial < 4000; ++trial) {
      const double depth = trial % 5 == 0 ? 0.3 * pos(rng) : 0.5 + 80.0 * pos(rng) * pos(rng);
      glm::dvec3 lo(unit(rng) * depth, unit(rng) * depth, -depth);
      glm::dvec3 hi = lo + glm::dvec3(3.0 * pos(rng), 3.0 * pos(rng), 3.0 * pos(rng));
      if (trial % 13 == 0) hi.x = lo.x;  // flat
      if (trial % 17 == 0) (trial % 2 ? lo.y : hi.z) = nan;
      if (trial % 19 == 0) (trial % 2 ? hi.x : lo.z) = trial % 3 ? inf : -inf;
      glm::dvec3 corners[8];
      box_corners(lo, hi, corners);
      const PixelRect want = g.box_rect(corners), got = g.box_rect(lo, hi);
      EXPECT_EQ(got.x0, want.x0) << trial;
      EXPECT_EQ(got.x1, want.x1) << trial;
      EXPECT_EQ(got.y0, want.y0) << trial;
      EXPECT_EQ(got.y1, want.y1) << trial;
      ++boxes;
      whole += want.x0 == 0 && want.y0 == 0 && want.x1 == g.width - 1 && want.y1 == g.height - 1;
    }
  }
  EXPECT_GT(whole, 100);  // the cases behind half the near plane were reached
  EXPECT_LT(whole, boxes / 2);
}

// draw_bond casts only the columns CylinderRows gives each row of the cylinder's rectangle: every
// pixel of the image whose ray the cast accepts must lie in the rectangle and in its row's span,
// for cylinders of every size, orientation and distance, in perspective and orthographic views.
// The half-bonds kept across steps: refit to moved atoms, their bounds and reach are the bits a
// build gives; a non-finite position or a bound of exactly zero makes the refit refuse.
TEST(BrickBondsRefit, GivesTheBitsOfABuildAndRefusesWhereItCannot) {
  testing::BondedSystem s = testing::polymer_melt(60, 40, 18.0);
  ParticleDescription p;
  p.count = int64_t(s.atoms());
  p.position = {s.xyz.data(), DataType::kFloat64, 0};
  ParticleArrays particles;
  EXPECT_OK(ParticleArrays::validate(p, &particles));
  BondDescription b = bond_pairs(s);
  BondArrays bonds;
  EXPECT_OK(BondArrays::validate(b, particles, &bonds));
  PeriodicBox box;
  box.length = {s.box, s.box, s.box};
  box.periodic = {true, true, true};
  BrickSet bricks = build_bricks(particles, BrickOptions{});
  BrickBonds kept;
  build_brick_bonds(particles, bonds, bricks, &box, &kept);
  const uint64_t order = bricks.order_generation;
  // Every atom moves a little: the bricks refit with every particle in its slot.
  for (size_t c = 0; c < s.xyz.size(); ++c) s.xyz[c] += 0.01 * std::sin(double(c));
  ASSERT_TRUE(refit_bricks(particles, 1.25, &bricks));
  EXPECT_EQ(bricks.order_generation, order);
  ASSERT_TRUE(refit_brick_bonds(particles, bonds, bricks, &box, &kept));
  BrickBonds built;
  build_brick_bonds(particles, bonds, bricks, &box, &built);
  expect_same_bits(kept, built);
  const auto atom = size_t(s.bonds[0]);
  const double x0 = s.xyz[3 * atom];
  // A NaN end: the build words the bond, the refit leaves it to the build.
  s.xyz[3 * atom] = std::nan("");
  EXPECT_FALSE(refit_brick_bonds(particles, bonds, bricks, &box, &kept));
  // So does an infinite one, also where no axis wraps (minimum_image's shortcut lets it by).
  s.xyz[3 * atom] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(refit_brick_bonds(particles, bonds, bricks, &box, &kept));
  EXPECT_FALSE(refit_brick_bonds(particles, bonds, bricks, nullptr, &kept));
  s.xyz[3 * atom] = x0;
  // A particle moved far: the bricks re-sort it, so their order is new.
  s.xyz[0] += 3.0 * s.box;
  ASSERT_TRUE(refit_bricks(particles, 1.25, &bricks));
  EXPECT_NE(bricks.order_generation, order);
}

// With ghosts: under kListedOnce a ghost's halves are filed under their owned atoms, so one
// ghost's halves lie in several runs (and bricks) and its reach is the longest over all of them;
// under kListedByBoth the ghosts' halves are the other ranks'. The refit gives a build's bits.
TEST(BrickBondsRefit, GivesTheBitsOfABuildWithGhosts) {
  for (const BondListing listing : {BondListing::kListedOnce, BondListing::kListedByBoth}) {
    testing::BondedSystem s = testing::polymer_melt(60, 40, 18.0);
    // Every fourth atom of a chain becomes a ghost, moved after the owned ones: a ghost inside a
    // chain is bonded to two owned atoms.
    std::vector<int64_t> moved(s.atoms());
    int64_t owned = 0;
    for (size_t i = 0; i < s.atoms(); ++i)
      if (i % 4 != 1) moved[i] = owned++;
    for (size_t i = 0, ghost = size_t(owned); i < s.atoms(); ++i)
      if (i % 4 == 1) moved[i] = int64_t(ghost++);
    std::vector<double> xyz(s.xyz.size());
    std::vector<int64_t> id(s.atoms());
    for (size_t i = 0; i < s.atoms(); ++i) {
      for (int c = 0; c < 3; ++c) xyz[3 * size_t(moved[i]) + size_t(c)] = s.xyz[3 * i + size_t(c)];
      id[size_t(moved[i])] = s.id[i];
    }
    s.xyz = xyz, s.id = id;
    for (int64_t &atom : s.bonds) atom = moved[size_t(atom)];
    ParticleDescription p;
    p.count = owned;
    p.position = {s.xyz.data(), DataType::kFloat64, 0};
    p.id = {s.id.data(), DataType::kInt64, 0};
    ParticleArrays particles;
    EXPECT_OK(ParticleArrays::validate(p, &particles));
    BondDescription b = bond_pairs(s);
    b.ghost_count = int64_t(s.atoms()) - owned;
    b.listing = listing;
    BondArrays bonds;
    EXPECT_OK(BondArrays::validate(b, particles, &bonds));
    // Under kListedByBoth, z is not periodic: its bonds across the box are drawn as they are.
    PeriodicBox box;
    box.length = {s.box, s.box, s.box};
    box.periodic = {true, true, listing == BondListing::kListedOnce};
    BrickSet bricks = build_bricks(particles, BrickOptions{});
    BrickBonds kept;
    build_brick_bonds(particles, bonds, bricks, &box, &kept);
    // Some ghost has halves in more than one run: the case the refit must merge.
    std::vector<int> runs(s.atoms(), 0);
    for (size_t h = 0; h < kept.halves.size(); ++h)
      if (h == 0 || kept.halves[h].atom != kept.halves[h - 1].atom) ++runs[kept.halves[h].atom];
    if (listing == BondListing::kListedOnce)
      EXPECT_GT(*std::max_element(runs.begin() + owned, runs.end()), 1);
    for (size_t c = 0; c < s.xyz.size(); ++c) s.xyz[c] += 0.01 * std::cos(double(c));
    ASSERT_TRUE(refit_bricks(particles, 1.25, &bricks));
    ASSERT_TRUE(refit_brick_bonds(particles, bonds, bricks, &box, &kept));
    BrickBonds built;
    build_brick_bonds(particles, bonds, bricks, &box, &built);
    expect_same_bits(kept, built);
    // A ghost only ever a partner (kListedByBoth keeps no ghost's half), moved to infinity along
    // z, which does not wrap: the refit refuses, as for a NaN.
    if (listing == BondListing::kListedByBoth) {
      s.xyz[3 * size_t(owned) + 2] = std::numeric_limits<double>::infinity();
      EXPECT_FALSE(refit_brick_bonds(particles, bonds, bricks, &box, &kept));
    }
  }
}

// A bound of exactly zero: which of -0 and +0 it holds depends on the order the ends are met
// in, so the refit refuses and the build decides.
TEST(BrickBondsRefit, RefusesABoundOfExactlyZero) {
  std::vector<double> xyz = {0.0, 1.0, 1.0, 1.0, 1.0, 1.0};
  std::vector<int64_t> pair = {0, 1};
  ParticleDescription p;
  p.count = 2;
  p.position = {xyz.data(), DataType::kFloat64, 0};
  ParticleArrays particles;
  EXPECT_OK(ParticleArrays::validate(p, &particles));
  BondDescription b;
  b.count = 1;
  b.first = {pair.data(), DataType::kInt64, 16};
  b.second = {pair.data() + 1, DataType::kInt64, 16};
  BondArrays bonds;
  EXPECT_OK(BondArrays::validate(b, particles, &bonds));
  const BrickSet bricks = build_bricks(particles, BrickOptions{});
  BrickBonds halves;
  build_brick_bonds(particles, bonds, bricks, nullptr, &halves);
  EXPECT_FALSE(refit_brick_bonds(particles, bonds, bricks, nullptr, &halves));
  xyz[0] = 0.5;  // off the plane: the refit stands
  EXPECT_TRUE(refit_brick_bonds(particles, bonds, bricks, nullptr, &halves));
  EXPECT_EQ(halves.lo[0].x, 0.5);
}

// Both casts: the double one (CylinderCast) and, for cylinders wholly in front of the eye, the
// float one (CentredCylinder), whose rays are built from float steps.
TEST(CylinderRows, HoldEveryPixelTheCastAccepts) {
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), pos(0.0, 1.0);
  int64_t hits = 0, float_hits = 0, cast = 0, pixels = 0;
  for (const bool ortho : {false, true}) {
    const ViewGeometry g = small_view(ortho);
    PixelRays rays;
    rays.reset(g);
    for (int trial = 0; trial < 400; ++trial) {
      const double depth = 2.0 + 60.0 * pos(rng) * pos(rng);
      const glm::dvec3 a(unit(rng) * 0.6 * depth, unit(rng) * 0.4 * depth, -depth);
      glm::dvec3 axis(unit(rng), unit(rng), unit(rng));
      if (trial % 7 == 0) axis = glm::dvec3(0.0, 0.0, 1.0);   // end on
      if (trial % 11 == 0) axis = glm::dvec3(1.0, 0.0, 0.0);  // along the rows
      const double length = 0.05 + 4.0 * pos(rng), r = 0.02 + 1.5 * pos(rng) * pos(rng);
      const glm::dvec3 u = glm::normalize(axis), b = a + length * u;
      double near_depth;
      const PixelRect rect = cylinder_rect(g, a, b, r, &near_depth);
      const CylinderRows rows(g, rays, a, u, r, rect);
      const CylinderCast cylinder(ortho, a, u, length, r);
      std::optional<CentredCylinder> centred;
      if (CentredCylinder::applies(g, a, b, r)) centred.emplace(g, rays, a, u, length, r);
      for (int y = 0; y < g.height; ++y) {
        int lo = 0, hi = -1;
        const bool any = y >= rect.y0 && y <= rect.y1 && rows.span(rays, y, &lo, &hi);
        for (int x = 0; x < g.width; ++x) {
          CylinderHit hit;
          ++pixels;
          if (any && x >= lo && x <= hi) ++cast;
          if (centred) {
            float wz, lambert2;
            cylinder_pixel(*centred, x - centred->ref_x, y - centred->ref_y, &wz, &lambert2);
            if (wz != kCylinderMiss) {
              ++float_hits;
              ASSERT_TRUE(any && x >= lo && x <= hi)
                  << (ortho ? "orthographic" : "perspective") << " trial " << trial
                  << " float cast, pixel " << x << "," << y << " span " << lo << ".." << hi;
            }
          }
          if (!cylinder.cast(rays.x(x), rays.y(y), &hit)) continue;
          ++hits;
          ASSERT_TRUE(any && x >= lo && x <= hi)
              << (ortho ? "orthographic" : "perspective") << " trial " << trial << " pixel " << x
              << "," << y << " rect " << rect.x0 << ".." << rect.x1 << " x " << rect.y0 << ".."
              << rect.y1 << " span " << lo << ".." << hi;
        }
      }
    }
  }
  EXPECT_GT(hits, 10000);  // the cylinders are seen
  EXPECT_GT(float_hits, 10000);
  EXPECT_LT(cast, pixels / 4);  // and the spans leave most of the image out
  std::printf("cylinder rows: %lld pixels hit (%lld by the float cast), %lld cast, of %lld\n",
              static_cast<long long>(hits), static_cast<long long>(float_hits),
              static_cast<long long>(cast), static_cast<long long>(pixels));
}

// The float cast near the silhouette of thin, distant cylinders in a large image, where a ray
// built from float steps is furthest (relative to the cylinder) from the double ray CylinderRows
// reasons about: its spans still hold every pixel the float cast accepts.
TEST(CylinderRows, HoldTheFloatCastOfThinDistantCylinders) {
  std::mt19937_64 rng(20261204);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), pos(0.0, 1.0);
  int64_t float_hits = 0;
  for (const bool ortho : {false, true}) {
    ViewGeometry g = small_view(ortho);
    g.width = 2048, g.height = 1536;
    PixelRays rays;
    rays.reset(g);
    for (int trial = 0; trial < 300; ++trial) {
      const double depth = 20.0 + 150.0 * pos(rng);
      const glm::dvec3 a(unit(rng) * 0.6 * depth * (ortho ? 0.02 : 1.0),
                         unit(rng) * 0.4 * depth * (ortho ? 0.02 : 1.0), -depth);
      const glm::dvec3 u = glm::normalize(glm::dvec3(unit(rng), unit(rng), unit(rng)));
      const double length = (ortho ? 0.05 : 1.0) * (0.5 + 8.0 * pos(rng));
      const double r = (ortho ? 0.0005 : 0.01) * (0.2 + pos(rng));
      const glm::dvec3 b = a + length * u;
      double near_depth;
      const PixelRect rect = cylinder_rect(g, a, b, r, &near_depth);
      if (rect.empty() || !CentredCylinder::applies(g, a, b, r)) continue;
      const CylinderRows rows(g, rays, a, u, r, rect);
      const CentredCylinder centred(g, rays, a, u, length, r);
      for (int y = rect.y0; y <= rect.y1; ++y) {
        int lo = 0, hi = -1;
        const bool any = rows.span(rays, y, &lo, &hi);
        for (int x = rect.x0; x <= rect.x1; ++x) {
          float wz, lambert2;
          cylinder_pixel(centred, x - centred.ref_x, y - centred.ref_y, &wz, &lambert2);
          if (wz == kCylinderMiss) continue;
          ++float_hits;
          ASSERT_TRUE(any && x >= lo && x <= hi)
              << (ortho ? "orthographic" : "perspective") << " trial " << trial << " pixel " << x
              << "," << y << " span " << lo << ".." << hi;
        }
      }
    }
  }
  EXPECT_GT(float_hits, 5000);
}

// draw_bond skips the pixels already nearer than the cylinder's nearest point (early depth
// reject): over a frame that random spheres already drew, its result must be that of casting
// every pixel - the cylinder drawn alone, merged by depth with ties to the smaller color, as
// compositing does - for cylinders in front of, among and behind the spheres, in perspective and
// orthographic views.
TEST(CpuBondRaster, EarlyDepthRejectLeavesTheImageOfCastingEveryPixel) {
  std::mt19937_64 rng(20261203);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), pos(0.0, 1.0);
  const uint8_t background[4] = {10, 20, 30, 255};
  int64_t kept_old = 0, won = 0;
  for (const bool ortho : {false, true}) {
    const ViewGeometry g = small_view(ortho);
    for (int trial = 0; trial < 150; ++trial) {
      const double depth = 3.0 + 20.0 * pos(rng);
      const glm::dvec3 a(unit(rng) * 0.4 * depth, unit(rng) * 0.3 * depth, -depth);
      const glm::dvec3 u = glm::normalize(glm::dvec3(unit(rng), unit(rng), unit(rng)));
      const double length = 0.3 + 2.0 * pos(rng), r = 0.1 + 0.4 * pos(rng);
      const glm::dvec3 b = a + length * u;
      const uint8_t rgb[3] = {uint8_t(trial), 200, uint8_t(255 - trial)};
      Frame drawn, alone;
      CpuSphereRaster raster, single;
      CpuSphereRaster::clear_target(g, background, &drawn);
      CpuSphereRaster::clear_target(g, background, &alone);
      raster.begin_strip(g, &drawn, 0, g.width - 1);
      single.begin_strip(g, &alone, 0, g.width - 1);
      // Spheres round the cylinder, some in front of it, some behind, some through it.
      for (int k = 0; k < 12; ++k) {
        const glm::dvec3 c =
            a + pos(rng) * length * u + glm::dvec3(unit(rng), unit(rng), unit(rng)) * (2.0 * r);
        const double radius = r * (0.5 + 1.5 * pos(rng));
        const uint8_t sphere_rgb[3] = {uint8_t(40 * k), 90, 120};
        raster.draw(c, radius, sphere_rgb, g.sphere_rect_tight(c, radius, 0.05));
      }
      const Frame before = drawn;
      double near_depth;
      const PixelRect rect = cylinder_rect(g, a, b, r, &near_depth);
      raster.draw_bond(a, b, r, rgb, rect);
      single.draw_bond(a, b, r, rgb, rect);
      const auto word = [](const Frame &f, size_t p) {
        return uint32_t(f.rgba[4 * p]) << 24 | uint32_t(f.rgba[4 * p + 1]) << 16 |
               uint32_t(f.rgba[4 * p + 2]) << 8 | f.rgba[4 * p + 3];
      };
      for (size_t p = 0; p < before.depth.size(); ++p) {
        const bool nearer = alone.depth[p] < before.depth[p] ||
                            (alone.depth[p] == before.depth[p] && word(alone, p) < word(before, p));
        const Frame &expect = nearer ? alone : before;
        ASSERT_EQ(drawn.depth[p], expect.depth[p]) << "trial " << trial << " pixel " << p;
        ASSERT_EQ(word(drawn, p), word(expect, p)) << "trial " << trial << " pixel " << p;
        const bool covered_by_cylinder = alone.depth[p] < kBackgroundDepth;
        kept_old += covered_by_cylinder && !nearer;
        won += nearer;
      }
    }
  }
  // Both outcomes occur often: the cylinder wins pixels and loses others to nearer spheres.
  EXPECT_GT(won, 1000);
  EXPECT_GT(kept_old, 1000);
}

// draw_bond casts a cylinder wholly in front of the eye in float through cylinder_pixel, in
// vector code picked for the CPU at load time (AVX2 here where the CPU has it): its depths are
// bit for bit those of cylinder_pixel run one pixel at a time in this file, built for the
// baseline instruction set (and, as the raster, without fused multiply-adds:
// tests/render/CMakeLists.txt), so an image does not depend on the vector width. Cylinders in
// both projections, some reaching past the image's edges and its last row.
TEST(CpuBondRaster, FloatCastIsThePixelFunctionAtAnyVectorWidth) {
  std::mt19937_64 rng(20261205);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), pos(0.0, 1.0);
  const uint8_t background[4] = {0, 0, 0, 255};
  int64_t compared = 0, hit = 0;
  for (const bool ortho : {false, true}) {
    const ViewGeometry g = small_view(ortho);
    PixelRays rays;
    rays.reset(g);
    for (int trial = 0; trial < 200; ++trial) {
      const double depth = 2.0 + 30.0 * pos(rng);
      const double spread = ortho ? 1.0 / depth : 1.0;
      const glm::dvec3 a(unit(rng) * 0.7 * depth * spread, unit(rng) * 0.5 * depth * spread,
                         -depth);
      const glm::dvec3 u = glm::normalize(glm::dvec3(unit(rng), unit(rng), unit(rng)));
      const double length = 0.3 + 3.0 * pos(rng), r = 0.05 + 0.6 * pos(rng);
      const glm::dvec3 b = a + length * u;
      if (!CentredCylinder::applies(g, a, b, r)) continue;
      Frame frame;
      CpuSphereRaster raster;
      CpuSphereRaster::clear_target(g, background, &frame);
      raster.begin_strip(g, &frame, 0, g.width - 1);
      double near_depth;
      const PixelRect rect = cylinder_rect(g, a, b, r, &near_depth);
      const uint8_t rgb[3] = {200, 100, 50};
      raster.draw_bond(a, b, r, rgb, rect);
      const CentredCylinder cylinder(g, rays, a, u, length, r);
      for (int y = 0; y < g.height; ++y)
        for (int x = 0; x < g.width; ++x) {
          float wz = kCylinderMiss, lambert2;
          if (x >= rect.x0 && x <= rect.x1 && y >= rect.y0 && y <= rect.y1)
            cylinder_pixel(cylinder, x - cylinder.ref_x, y - cylinder.ref_y, &wz, &lambert2);
          const float expect = wz < kBackgroundDepth ? wz : kBackgroundDepth;
          const float got = frame.depth[size_t(y) * size_t(g.width) + size_t(x)];
          ++compared;
          hit += expect < kBackgroundDepth;
          ASSERT_EQ(std::memcmp(&got, &expect, sizeof(float)), 0)
              << (ortho ? "orthographic" : "perspective") << " trial " << trial << " pixel " << x
              << "," << y << ": " << got << " vs " << expect;
        }
    }
  }
  EXPECT_GT(hit, 10000);
  std::printf("float cast: %lld of %lld pixels hit, all as cylinder_pixel\n",
              static_cast<long long>(hit), static_cast<long long>(compared));
}

}  // namespace
}  // namespace lantern
