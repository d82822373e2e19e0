// Culling against brute force: frustum culling drops nothing that is drawn, hzb renders images
// bit-identical to drawing every particle (outside, inside, orthographic, mixed radii), auto
// picks what pays, cutting planes and level of detail do what they say.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/culling/cull_stage.h"
#include "core/culling/hzb.h"
#include "core/pipeline/rank_draw.h"
#include "core/pipeline/scene_settings.h"
#include "core/render/cpu_sphere_pass.h"
#include "core/render/cpu_sphere_raster.h"
#include "core/render/gl/gl_session.h"
#include "core/render/point_splats.h"
#include "core/render/sphere_instances.h"
#include "core/view/cylinder_bounds.h"
#include "tests/support/gl_test.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

struct Cloud {
  std::vector<double> xyz;
  std::vector<double> radius;  // empty: the scene's radius
  std::vector<int32_t> type;
  ParticleArrays arrays() const {
    ParticleDescription p{};
    p.count = int64_t(xyz.size() / 3);
    p.position = {xyz.data(), DataType::kFloat64, 0};
    if (!radius.empty()) p.radius = {radius.data(), DataType::kFloat64, 0};
    p.type = {type.data(), DataType::kInt32, 0};
    ParticleArrays a;
    EXPECT_OK(ParticleArrays::validate(p, &a));
    return a;
  }
  void add(double x, double y, double z) {
    xyz.insert(xyz.end(), {x, y, z});
    type.push_back(int32_t(type.size() % 5));
  }
};

// An fcc crystal of n^3 cells, lattice constant a, shuffled so that the published order is not
// spatial (brute force then draws in an order unrelated to the bricks').
Cloud fcc(int n, double a, unsigned seed = 1) {
  Cloud c;
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::vector<std::array<double, 3>> pts;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        for (const auto &b : basis) pts.push_back({(x + b[0]) * a, (y + b[1]) * a, (z + b[2]) * a});
  std::shuffle(pts.begin(), pts.end(), std::mt19937(seed));
  for (const auto &p : pts) c.add(p[0], p[1], p[2]);
  return c;
}

class CullingTest : public testing::GlTest {
 protected:
  static SceneConfig scene(int size, double radius, OcclusionMode mode) {
    SceneConfig s;
    s.width = s.height = size;
    s.radius = radius;
    s.per_particle_radius = false;
    s.culling.occlusion = mode;
    return s;
  }

  Camera camera(const SceneConfig &s, const Cloud &c, const CameraConfig &cfg) {
    glm::dvec3 lo(1e300), hi(-1e300);
    for (size_t i = 0; i < c.xyz.size(); i += 3) {
      lo = glm::min(lo, glm::dvec3(c.xyz[i], c.xyz[i + 1], c.xyz[i + 2]));
      hi = glm::max(hi, glm::dvec3(c.xyz[i], c.xyz[i + 1], c.xyz[i + 2]));
    }
    double r = s.radius;
    for (double v : c.radius) r = std::max(r, v);
    Camera cam;
    EXPECT_OK(make_camera(cfg, lo, hi, r, s.width, s.height, &cam));
    return cam;
  }

  Frame render(const std::vector<SphereInstance> &inst, const Camera &cam) {
    const uint8_t bg[4] = {255, 255, 255, 255};
    Frame f;
    RenderTimings t;
    EXPECT_OK(renderer_->render(cam.render_view(bg), inst.data(), inst.size(), &f, &t));
    return f;
  }

  // Renders brute force and the culled scene as the pipeline draws it with OpenGL; returns the
  // culling stats and the number of differing pixels (color or depth).
  CullStats compare(const Cloud &c, const SceneConfig &s, const Camera &cam, int64_t *differ) {
    const ParticleArrays p = c.arrays();
    const InstanceRecipe recipe =
        make_recipe(p, shading_settings(s), radius_rule(s, p), cam, Extent{});
    std::vector<SphereInstance> all;
    build_all_instances(recipe, &all);
    const Frame brute = render(all, cam);
    const BrickSet bricks = build_bricks(p, BrickOptions{});
    SceneConfig on_gl = s;
    on_gl.renderer = RendererChoice::kOpenGl;
    RankScene scene(p, bricks, cam, on_gl);
    scene.renderer = renderer_;
    RankDrawScratch scratch;
    Frame culled;
    RankDraw drawn;
    EXPECT_OK(draw_scene_on_rank(scene, &scratch, &culled, &drawn));
    EXPECT_EQ(drawn.renderer, "opengl");
    *differ = differing_pixels(brute, culled);
    return drawn.cull;
  }

  // The scene drawn by the CPU raster as the pipeline draws it without OpenGL, in
  // s.culling.occlusion mode (one the CPU pass serves itself).
  Frame raster(const Cloud &c, const SceneConfig &s, const Camera &cam, CullStats *stats) {
    const ParticleArrays p = c.arrays();
    const BrickSet bricks = build_bricks(p, BrickOptions{});
    RankDrawScratch scratch;
    Frame frame;
    RankDraw drawn;
    EXPECT_OK(draw_scene_on_rank(RankScene(p, bricks, cam, s), &scratch, &frame, &drawn));
    EXPECT_EQ(drawn.cull.occlusion.find("no OpenGL"), std::string::npos) << drawn.cull.occlusion;
    expect_background_outside_drawn_within(frame);
    *stats = drawn.cull;
    return frame;
  }

  // Where the CPU pass says it drew (Frame::drawn_within, which compositing's scan trusts), every
  // pixel outside holds the background at background depth. Absent only where points were
  // splatted after the raster.
  static void expect_background_outside_drawn_within(const Frame &frame) {
    if (!frame.drawn_within) return;
    const DrawnWithin &w = *frame.drawn_within;
    int64_t outside = 0, wrong = 0;
    for (int y = 0; y < frame.height; ++y)
      for (int x = 0; x < frame.width; ++x) {
        if (x >= w.x0 && x < w.x1 && y >= w.y0 && y < w.y1) continue;
        ++outside;
        const size_t i = frame.index(x, y);
        if (frame.depth[i] != kBackgroundDepth || std::memcmp(&frame.rgba[4 * i], w.background, 4))
          ++wrong;
      }
    EXPECT_EQ(wrong, 0) << "of " << outside << " pixels outside [" << w.x0 << ", " << w.x1
                        << ") x [" << w.y0 << ", " << w.y1 << ")";
  }

  static int64_t differing_pixels(const Frame &a, const Frame &b) {
    int64_t n = 0;
    for (size_t i = 0; i < a.pixel_count(); ++i)
      if (a.depth[i] != b.depth[i] || std::memcmp(&a.rgba[4 * i], &b.rgba[4 * i], 4) != 0) ++n;
    return n;
  }
};

CameraConfig orbit(double azimuth, double elevation, double zoom = 1.0) {
  CameraConfig cfg;
  cfg.azimuth = azimuth;
  cfg.elevation = elevation;
  cfg.zoom = zoom;
  return cfg;
}

TEST_F(CullingTest, FrustumCullingDropsNothingThatIsDrawn) {
  const Cloud c = fcc(14, 1.5874);
  SceneConfig s = scene(200, 0.5, OcclusionMode::kNone);
  for (const double zoom : {1.0, 3.0, 8.0}) {
    const Camera cam = camera(s, c, orbit(35, 25, zoom));
    int64_t differ = -1;
    const CullStats st = compare(c, s, cam, &differ);
    EXPECT_EQ(differ, 0) << "zoom " << zoom;
    if (zoom > 1.0) {
      EXPECT_GT(st.frustum_culled, 0) << "zoom " << zoom;
    }
    EXPECT_EQ(st.drawn + st.frustum_culled, st.candidates);
  }
}

TEST_F(CullingTest, HzbIsBitIdenticalFromOutsideAndCullsMost) {
  const Cloud c = fcc(16, 1.5874);
  const SceneConfig s = scene(384, 0.5, OcclusionMode::kHzb);
  for (const auto &cfg : {orbit(30, 20), orbit(0, 0), orbit(45, 35.26, 1.6)}) {
    const Camera cam = camera(s, c, cfg);
    int64_t differ = -1;
    const CullStats st = compare(c, s, cam, &differ);
    EXPECT_EQ(differ, 0) << "azimuth " << cfg.azimuth;
    EXPECT_GT(st.occlusion_culled, st.candidates / 2) << "azimuth " << cfg.azimuth;
  }
}

TEST_F(CullingTest, HzbIsBitIdenticalOrthographic) {
  const Cloud c = fcc(14, 1.5874, 2);
  const SceneConfig s = scene(320, 0.55, OcclusionMode::kHzb);
  CameraConfig cfg = orbit(20, 15);
  cfg.projection = Projection::kOrthographic;
  const Camera cam = camera(s, c, cfg);
  int64_t differ = -1;
  const CullStats st = compare(c, s, cam, &differ);
  EXPECT_EQ(differ, 0);
  EXPECT_GT(st.occlusion_culled, st.candidates / 2);
}

TEST_F(CullingTest, HzbIsBitIdenticalWithTheCameraInsideTheCrystal) {
  const Cloud c = fcc(16, 1.5874, 3);
  const SceneConfig s = scene(320, 0.5, OcclusionMode::kHzb);
  CameraConfig cfg;
  cfg.fov_y = 70;
  // Between lattice planes, looking along a skew direction through the crystal.
  cfg.position = std::array<double, 3>{12.1, 11.3, 12.6};
  cfg.look_at = {30, 22, 18};
  cfg.up = {0, 0, 1};
  const Camera cam = camera(s, c, cfg);
  int64_t differ = -1;
  const CullStats st = compare(c, s, cam, &differ);
  EXPECT_EQ(differ, 0);
  EXPECT_GT(st.frustum_culled, 0);
  EXPECT_GT(st.occlusion_culled, 0);
}

TEST_F(CullingTest, HzbIsBitIdenticalWithMixedRadiiInADenseCloud) {
  Cloud c;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 20.0), r(0.2, 1.2);
  for (int i = 0; i < 30000; ++i) {
    c.add(u(rng), u(rng), u(rng));
    c.radius.push_back(r(rng));
  }
  SceneConfig s = scene(320, 0.5, OcclusionMode::kHzb);
  s.per_particle_radius = true;
  for (const auto &cfg : {orbit(30, 20), orbit(200, -40, 2.5)}) {
    const Camera cam = camera(s, c, cfg);
    int64_t differ = -1;
    const CullStats st = compare(c, s, cam, &differ);
    EXPECT_EQ(differ, 0) << "azimuth " << cfg.azimuth;
    EXPECT_GT(st.occlusion_culled, 0);
  }
}

TEST_F(CullingTest, AutoSkipsOcclusionForASparseGasAndUsesHzbForASolid) {
  Cloud gas;
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(0.0, 200.0);
  for (int i = 0; i < 30000; ++i) gas.add(u(rng), u(rng), u(rng));
  SceneConfig s = scene(256, 0.3, OcclusionMode::kAuto);
  int64_t differ = -1;
  CullStats st = compare(gas, s, camera(s, gas, orbit(30, 20)), &differ);
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(st.occlusion.rfind("none (auto:", 0), 0u) << st.occlusion;
  EXPECT_FALSE(st.per_particle_frustum);  // everything in view: no per-particle work

  const Cloud solid = fcc(20, 1.5874);  // 32000: above the "few particles" threshold
  s = scene(384, 0.5, OcclusionMode::kAuto);
  st = compare(solid, s, camera(s, solid, orbit(30, 20)), &differ);
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(st.occlusion.rfind("hzb (auto: dense", 0), 0u) << st.occlusion;
}

TEST_F(CullingTest, CutPlanesDropParticlesOnThePositiveSide) {
  const Cloud c = fcc(10, 1.5874);
  SceneConfig s = scene(128, 0.5, OcclusionMode::kNone);
  CutPlane cut;
  cut.normal = {1, 0, 0};
  cut.offset = 7.0;
  s.cuts.push_back(cut);
  const ParticleArrays p = c.arrays();
  const BrickSet bricks = build_bricks(p, BrickOptions{});
  Culler culler;
  DrawList draw;
  const CullStats st = culler.run(p, bricks, camera(s, c, orbit(30, 20)), cull_settings(s),
                                  radius_rule(s, p), &draw);
  int64_t expect_kept = 0;
  for (size_t i = 0; i < c.xyz.size(); i += 3) expect_kept += c.xyz[i] <= 7.0;
  EXPECT_EQ(st.drawn, expect_kept);
  EXPECT_EQ(st.cut_culled, st.candidates - expect_kept);
  for (const uint64_t e : draw.spheres) EXPECT_LE(c.xyz[3 * entry_index(e)], 7.0);
}

TEST_F(CullingTest, BudgetIsServedFromBrickPrefixes) {
  const Cloud c = fcc(16, 1.5874);
  SceneConfig s = scene(256, 0.5, OcclusionMode::kNone);
  s.lod.budget = 4000;
  const ParticleArrays p = c.arrays();
  const BrickSet bricks = build_bricks(p, BrickOptions{});
  Culler culler;
  DrawList draw;
  const CullStats st = culler.run(p, bricks, camera(s, c, orbit(30, 20)), cull_settings(s),
                                  radius_rule(s, p), &draw);
  EXPECT_LE(st.drawn, 4000 + int64_t(bricks.bricks.size()));
  EXPECT_GE(st.drawn, 3500);
  EXPECT_EQ(st.lod_dropped + st.drawn, st.candidates);
  for (const uint64_t e : draw.spheres) EXPECT_GT(entry_scale(e), 1.0f);  // spheres grew
}

TEST_F(CullingTest, ScreenSpaceRuleAndPointPathTakeOverSubPixelSpheres) {
  const Cloud c = fcc(20, 1.5874);
  SceneConfig s = scene(64, 0.2, OcclusionMode::kNone);  // spheres far below a pixel
  const ParticleArrays p = c.arrays();
  const BrickSet bricks = build_bricks(p, BrickOptions{});
  const Camera cam = camera(s, c, orbit(30, 20));
  Culler culler;
  DrawList draw;
  s.lod.min_pixels = 3.0;
  CullStats st = culler.run(p, bricks, cam, cull_settings(s), radius_rule(s, p), &draw);
  EXPECT_LT(st.drawn, st.candidates / 4);
  EXPECT_EQ(st.drawn + st.lod_dropped, st.candidates);
  s.lod.min_pixels = 0.0;
  s.lod.point_path = true;
  st = culler.run(p, bricks, cam, cull_settings(s), radius_rule(s, p), &draw);
  EXPECT_EQ(st.splatted, st.candidates);  // every sphere is below half a pixel here
  EXPECT_EQ(st.drawn, 0);
  // The splats land in the frame, nearest first.
  Frame f = render({}, cam);
  const InstanceRecipe recipe =
      make_recipe(p, shading_settings(s), radius_rule(s, p), cam, Extent{});
  splat_points(
      p, false, s.radius, draw.points, culler.geometry(),
      [&recipe](int64_t i) { return recipe.color(i); }, &f);
  int64_t written = 0;
  for (const float d : f.depth) written += d < 1.0f;
  EXPECT_GT(written, 1000);
}

TEST_F(CullingTest, HzbIsBitIdenticalOnRandomScenesAndCameras) {
  // Boxes, slabs and lattices, near the origin or far from it, uniform or mixed radii, cameras
  // outside or inside, perspective or orthographic, odd image sizes (fixed seed).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int it = 0; it < 8; ++it) {
    Cloud c;
    const int n = 3000 + int(u(rng) * 9000);
    const double side = 5 + u(rng) * 25, far = u(rng) < 0.3 ? 1e5 * u(rng) : 0.0;
    const bool slab = u(rng) < 0.3, mixed = u(rng) < 0.5;
    for (int i = 0; i < n; ++i) {
      c.add(far + u(rng) * side, far + u(rng) * side, far + u(rng) * side * (slab ? 0.2 : 1.0));
      if (mixed) c.radius.push_back(0.1 + u(rng));
    }
    SceneConfig s = scene(64 + int(u(rng) * 250), 0.3 + u(rng), OcclusionMode::kHzb);
    s.height = 64 + int(u(rng) * 250);
    s.per_particle_radius = mixed;
    CameraConfig cfg = orbit(u(rng) * 360, -80 + u(rng) * 160, 0.5 + 3 * u(rng));
    cfg.fov_y = 20 + 70 * u(rng);
    if (u(rng) < 0.25) cfg.projection = Projection::kOrthographic;
    if (u(rng) < 0.4) {  // inside the cloud, looking somewhere across it
      cfg.position =
          std::array<double, 3>{far + u(rng) * side, far + u(rng) * side, far + u(rng) * side};
      cfg.look_at = {far + u(rng) * side + 0.1, far + u(rng) * side, far + u(rng) * side};
    }
    int64_t differ = -1;
    compare(c, s, camera(s, c, cfg), &differ);
    EXPECT_EQ(differ, 0) << "case " << it;
  }
}

TEST_F(CullingTest, CpuRasterWithHzbIsBitIdenticalToCpuRasterOfEverything) {
  // The fused pass skips only spheres that could not change a pixel, and depth ties go to the
  // smaller color whatever the drawing order: so the images are equal bit for bit.
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int64_t culled = 0;
  for (int it = 0; it < 10; ++it) {
    Cloud c = it < 2 ? fcc(10, 1.6, unsigned(it + 1)) : Cloud{};
    const bool mixed = it >= 2 && u(rng) < 0.5;
    if (it >= 2) {
      const int n = 3000 + int(u(rng) * 9000);
      const double side = 5 + u(rng) * 25, far = u(rng) < 0.3 ? 1e5 * u(rng) : 0.0;
      for (int i = 0; i < n; ++i) {
        c.add(far + u(rng) * side, far + u(rng) * side, far + u(rng) * side);
        if (mixed) c.radius.push_back(0.1 + u(rng));
      }
    }
    SceneConfig s = scene(64 + int(u(rng) * 400), 0.3 + u(rng), OcclusionMode::kHzb);
    s.height = 64 + int(u(rng) * 400);
    s.per_particle_radius = mixed;
    s.renderer = RendererChoice::kCpu;
    CameraConfig cfg = orbit(u(rng) * 360, -80 + u(rng) * 160, 0.5 + 3 * u(rng));
    if (u(rng) < 0.3) cfg.projection = Projection::kOrthographic;
    const Camera cam = camera(s, c, cfg);
    CullStats with, without;
    const Frame fused = raster(c, s, cam, &with);
    s.culling.occlusion = OcclusionMode::kNone;
    const Frame all = raster(c, s, cam, &without);
    ASSERT_TRUE(fused.drawn_within.has_value());  // checked in raster()
    ASSERT_TRUE(all.drawn_within.has_value());
    EXPECT_EQ(without.occlusion_culled, 0);
    EXPECT_EQ(differing_pixels(fused, all), 0) << "case " << it;
    culled += with.occlusion_culled;
  }
  EXPECT_GT(culled, 0);
}

TEST_F(CullingTest, CpuRasterCullsTheHiddenCrystalAndMatchesOpenGl) {
  // 32 000 fcc atoms from outside: the fused pass draws only the surface, and its image is
  // the OpenGL image except where float and double rounding disagree by a level or a pixel.
  const Cloud c = fcc(20, 1.6);
  SceneConfig s = scene(512, 0.5, OcclusionMode::kHzb);
  s.renderer = RendererChoice::kCpu;
  const Camera cam = camera(s, c, orbit(30, 20));
  CullStats st;
  const Frame cpu = raster(c, s, cam, &st);
  EXPECT_GT(double(st.occlusion_culled) / double(st.candidates), 0.7);

  const ParticleArrays p = c.arrays();
  std::vector<SphereInstance> all;
  build_all_instances(make_recipe(p, shading_settings(s), radius_rule(s, p), cam, Extent{}), &all);
  const Frame gl = render(all, cam);
  int64_t background_mismatch = 0, off_by_more = 0;
  double squared = 0.0;
  for (size_t i = 0; i < gl.pixel_count(); ++i) {
    background_mismatch += (gl.depth[i] == kBackgroundDepth) != (cpu.depth[i] == kBackgroundDepth);
    for (int k = 0; k < 3; ++k) {
      const int d = int(gl.rgba[4 * i + k]) - int(cpu.rgba[4 * i + k]);
      squared += d * d;
      off_by_more += std::abs(d) > 1;
    }
  }
  const double psnr = 10.0 * std::log10(255.0 * 255.0 / (squared / (3.0 * gl.pixel_count())));
  EXPECT_LE(background_mismatch, 20);  // silhouette pixels within rounding of a pixel centre
  EXPECT_LE(off_by_more, 50);          // depth ties between touching spheres may flip
  EXPECT_GT(psnr, 50.0) << "PSNR " << psnr;
  std::printf(
      "cpu vs opengl: PSNR %.1f dB, %lld channel values off by > 1, %lld silhouette "
      "pixels differ, %lld of %lld spheres drawn\n",
      psnr, (long long)off_by_more, (long long)background_mismatch, (long long)st.drawn,
      (long long)st.candidates);
}

// How far an OpenGL image is from a CPU image of the same spheres.
struct RendererDifference {
  int64_t coverage = 0;     // pixels drawn by one renderer and background in the other
  int64_t off_by_more = 0;  // pixels drawn by both with a channel off by more than one level
  int max_channel = 0;      // largest channel difference over the pixels drawn by both
  void add(const RendererDifference &o) {
    coverage += o.coverage, off_by_more += o.off_by_more;
    max_channel = std::max(max_channel, o.max_channel);
  }
};

RendererDifference renderer_difference(const Frame &gl, const Frame &cpu) {
  RendererDifference d;
  for (size_t i = 0; i < gl.pixel_count(); ++i) {
    const bool gl_drawn = gl.depth[i] != kBackgroundDepth,
               cpu_drawn = cpu.depth[i] != kBackgroundDepth;
    if (gl_drawn != cpu_drawn) {
      ++d.coverage;
      continue;
    }
    int worst = 0;
    for (int k = 0; k < 4; ++k)
      worst = std::max(worst, std::abs(int(gl.rgba[4 * i + k]) - int(cpu.rgba[4 * i + k])));
    d.off_by_more += worst > 1;
    d.max_channel = std::max(d.max_channel, worst);
  }
  return d;
}

TEST_F(CullingTest, OpenGlMatchesCpuRasterWithTheCameraInsideACrystal) {
  // Random cameras inside an fcc crystal, both projections: the near plane cuts spheres, others
  // lie behind the eye, and every third camera sits inside an atom. OpenGL (every sphere drawn)
  // must agree with the CPU raster as closely as it does for a crystal seen from outside.
  const double a = 1.6;
  const Cloud c = fcc(8, a);  // 2048 atoms in a cube of side 12.8
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  RendererDifference inside, outside;
  int64_t drawn_pixels = 0;
  for (int it = 0; it < 16; ++it) {
    SceneConfig s = scene(120 + int(u(rng) * 200), 0.4 + 0.35 * u(rng), OcclusionMode::kNone);
    s.height = 120 + int(u(rng) * 200);
    s.renderer = RendererChoice::kCpu;
    CameraConfig cfg;
    if (it % 2 == 1) cfg.projection = Projection::kOrthographic;
    glm::dvec3 eye(3.0 + 6.8 * u(rng), 3.0 + 6.8 * u(rng), 3.0 + 6.8 * u(rng));
    if (it % 3 == 0)
      eye = glm::dvec3(4 * a, 4 * a, 4 * a) + 0.3 * s.radius * glm::dvec3(u(rng), u(rng), u(rng));
    const glm::dvec3 look(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    cfg.position = std::array<double, 3>{eye.x, eye.y, eye.z};
    cfg.look_at = {eye.x + look.x, eye.y + look.y, eye.z + look.z};
    cfg.up = {u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5};
    cfg.fov_y = 30.0 + 60.0 * u(rng);
    cfg.near_plane = 0.02 + 1.2 * u(rng);
    cfg.far_plane = 40.0;
    const Camera cam = camera(s, c, cfg);
    CullStats st;
    const Frame cpu = raster(c, s, cam, &st);
    const ParticleArrays p = c.arrays();
    std::vector<SphereInstance> all;
    build_all_instances(make_recipe(p, shading_settings(s), radius_rule(s, p), cam, Extent{}),
                        &all);
    const Frame gl = render(all, cam);
    const RendererDifference d = renderer_difference(gl, cpu);
    // From outside the renderers differ in a pixel or two where intersecting spheres' float and
    // double depths disagree; a clipped sphere would cost hundreds.
    EXPECT_LE(d.coverage, 5) << "case " << it;
    EXPECT_LE(d.off_by_more, 5) << "case " << it;
    inside.add(d);
    for (float z : cpu.depth) drawn_pixels += z != kBackgroundDepth;
    // The same crystal from outside, for scale: what the renderers differ by without any cut.
    CameraConfig orbit_cfg = orbit(360 * u(rng), -60 + 120 * u(rng));
    orbit_cfg.projection = cfg.projection;
    const Camera far_cam = camera(s, c, orbit_cfg);
    const Frame cpu_out = raster(c, s, far_cam, &st);
    std::vector<SphereInstance> all_out;
    build_all_instances(make_recipe(p, shading_settings(s), radius_rule(s, p), far_cam, Extent{}),
                        &all_out);
    outside.add(renderer_difference(render(all_out, far_cam), cpu_out));
  }
  std::printf(
      "opengl vs cpu, 16 cameras inside the crystal: %lld coverage, %lld off by > 1, max "
      "%d; from outside: %lld coverage, %lld off by > 1, max %d\n",
      (long long)inside.coverage, (long long)inside.off_by_more, inside.max_channel,
      (long long)outside.coverage, (long long)outside.off_by_more, outside.max_channel);
  EXPECT_GT(drawn_pixels, 100000);
}

TEST(CpuSphereRaster, DepthTiesGoToTheSmallerColorInAnyDrawingOrder) {
  // Two coincident spheres, red and blue, drawn in both orders: every pixel they cover is a
  // depth tie, and blue (R = 0) is the smaller color, so blue wins everywhere in both orders.
  Camera cam;
  ASSERT_OK(make_camera(CameraConfig{}, {-1, -1, -1}, {1, 1, 1}, 1.0, 64, 64, &cam));
  const ViewGeometry g = ViewGeometry::from_camera(cam, 4.0);
  const glm::dvec3 c = g.to_view(glm::dvec3(0.0));
  const uint8_t bg[4] = {0, 0, 0, 255}, red[3] = {255, 0, 0}, blue[3] = {0, 0, 255};
  Frame frames[2];
  for (int order = 0; order < 2; ++order) {
    CpuSphereRaster::clear_target(g, bg, &frames[order]);
    CpuSphereRaster raster;
    raster.begin_strip(g, &frames[order], 0, g.width - 1);
    const PixelRect rect = g.sphere_rect(c, 1.0);
    raster.draw(c, 1.0, order == 0 ? red : blue, rect);
    raster.draw(c, 1.0, order == 0 ? blue : red, rect);
  }
  int64_t covered = 0;
  for (size_t i = 0; i < frames[0].pixel_count(); ++i) {
    EXPECT_EQ(std::memcmp(&frames[0].rgba[4 * i], &frames[1].rgba[4 * i], 4), 0) << i;
    EXPECT_EQ(frames[0].depth[i], frames[1].depth[i]);
    if (frames[0].depth[i] != kBackgroundDepth) {
      ++covered;
      // Blue won: red holds only the white highlight, as green does.
      EXPECT_EQ(frames[0].rgba[4 * i + 0], frames[0].rgba[4 * i + 1]) << i;
      EXPECT_GT(frames[0].rgba[4 * i + 2], frames[0].rgba[4 * i + 1]) << i;
    }
  }
  EXPECT_GT(covered, 100);
}

TEST(CpuSphereRaster, CoveredIsFalseUntilEveryPixelHoldsSomethingNearer) {
  Camera cam;
  ASSERT_OK(make_camera(CameraConfig{}, {-1, -1, -1}, {1, 1, 1}, 1.0, 32, 32, &cam));
  const ViewGeometry g = ViewGeometry::from_camera(cam, 4.0);
  const uint8_t bg[4] = {0, 0, 0, 255}, white[3] = {255, 255, 255};
  Frame frame;
  CpuSphereRaster::clear_target(g, bg, &frame);
  CpuSphereRaster raster;
  raster.begin_strip(g, &frame, 0, g.width - 1);
  const glm::dvec3 c = g.to_view(glm::dvec3(0.0));
  const PixelRect small{14, 14, 17, 17};
  EXPECT_FALSE(raster.covered(small, -c.z + 2.0));  // nothing drawn yet
  EXPECT_TRUE(raster.draw(c, 1.0, white, g.sphere_rect(c, 1.0)));
  EXPECT_TRUE(raster.covered(small, -c.z + 2.0));                     // behind the sphere's middle
  EXPECT_FALSE(raster.covered(small, -c.z - 1.5));                    // in front of it
  EXPECT_FALSE(raster.covered(PixelRect{0, 0, 31, 31}, -c.z + 2.0));  // corners are background
}

// The CPU raster tests' view: the default camera framing the box offset + [-5, 5]^3 (spheres up to
// 0.5) in a w x h frame, perspective or orthographic, at scale 20.
Status box_view(int w, int h, bool orthographic, double offset, ViewGeometry *g) {
  CameraConfig cfg;
  if (orthographic) cfg.projection = Projection::kOrthographic;
  Camera cam;
  const Status s =
      make_camera(cfg, glm::dvec3(offset - 5), glm::dvec3(offset + 5), 0.5, w, h, &cam);
  if (s.ok()) *g = ViewGeometry::from_camera(cam, 20.0);
  return s;
}

TEST(Hzb, OccludersRasteriseTheSameDepthsFourColumnsAtATime) {
  // The same occluders added to two hzbs, one with the vector rows (where the processor has
  // AVX2) and one without: level 0 the same floats, for spheres of a fraction of a pixel to most
  // of the frame, at its edges, across its near plane and inside one another, in frames of widths
  // that leave every remainder of four.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int64_t covered_pixels = 0, covered_queries = 0;
  for (int it = 0; it < 24; ++it) {
    const int w = 41 + it + int(u(rng) * 200), h = 40 + int(u(rng) * 200);
    ViewGeometry g;
    ASSERT_OK(box_view(w, h, it % 6 == 5, 0.0, &g));
    Hzb vector, scalar;
    vector.reset(g), scalar.reset(g);
    for (int i = 0; i < 80; ++i) {
      const glm::dvec3 p(12 * u(rng) - 6, 12 * u(rng) - 6, 30 * u(rng) - 15);
      const double r = 0.01 + std::pow(u(rng), 3) * 3.0;
      const glm::dvec3 c = g.to_view(p);
      const PixelRect rect = g.sphere_rect(c, r);
      Hzb::vector_rows() = true;
      const bool a = vector.add_occluder(c, r, rect);
      Hzb::vector_rows() = false;
      const bool b = scalar.add_occluder(c, r, rect);
      ASSERT_EQ(a, b);
    }
    Hzb::vector_rows() = true;
    ASSERT_EQ(vector.depth().size(), scalar.depth().size());
    for (size_t k = 0; k < vector.depth().size(); ++k) {
      ASSERT_EQ(std::memcmp(&vector.depth()[k], &scalar.depth()[k], sizeof(float)), 0)
          << "case " << it << " pixel " << k << ": " << vector.depth()[k] << " against "
          << scalar.depth()[k];
      covered_pixels += std::isfinite(scalar.depth()[k]);
    }
    // And the pyramids above level 0, which each occluder's written columns update: the same
    // answers to queries of every size.
    for (int q = 0; q < 3000; ++q) {
      const int x0 = int(u(rng) * w), y0 = int(u(rng) * h);
      const int side = 1 + int(std::pow(u(rng), 2) * 64);
      const PixelRect rect{x0, y0, std::min(w - 1, x0 + side), std::min(h - 1, y0 + side)};
      const double z = g.near_plane + std::pow(u(rng), 2) * 40.0;
      ASSERT_EQ(vector.covered(rect, z), scalar.covered(rect, z))
          << "case " << it << " query " << q;
      covered_queries += scalar.covered(rect, z);
    }
  }
  EXPECT_GT(covered_pixels, 50000);
  EXPECT_GT(covered_queries, 1000);
}

TEST(CpuSphereRaster, PixelsDoNotDependOnTheRectangleOrItsTilesAndTheTightRectHoldsThemAll) {
  // Every sphere drawn once over the whole image and once over its tight rectangle, which starts
  // its tiles elsewhere and picks small tiles or the one-by-one path for small spheres: the
  // frames must agree bit for bit, so the rectangle and the tiling decide nothing.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const uint8_t bg[4] = {0, 0, 0, 255};
  int64_t drawn_pixels = 0;
  for (int it = 0; it < 40; ++it) {
    const double offset = it % 4 == 1 ? 1e4 : 0.0;
    const int w = 40 + int(u(rng) * 300), h = 40 + int(u(rng) * 300);
    ViewGeometry g;
    ASSERT_OK(box_view(w, h, it % 3 == 0, offset, &g));
    Frame whole, tight;
    CpuSphereRaster::clear_target(g, bg, &whole);
    CpuSphereRaster::clear_target(g, bg, &tight);
    CpuSphereRaster a, b;
    a.begin_strip(g, &whole, 0, w - 1);
    b.begin_strip(g, &tight, 0, w - 1);
    for (uint32_t i = 0; i < 60; ++i) {
      const glm::dvec3 p(offset + 12 * u(rng) - 6, offset + 12 * u(rng) - 6,
                         offset + 12 * u(rng) - 6);
      const double r = 0.003 + std::pow(u(rng), 3) * 1.5;  // from a fraction of a pixel to ~40 px
      const uint8_t rgb[3] = {uint8_t(40 + i), 200, uint8_t(255 - i)};
      const glm::dvec3 c = g.to_view(p);
      a.draw(c, r, rgb, PixelRect{0, 0, w - 1, h - 1});
      const PixelRect t = g.sphere_rect_tight(c, r, 0.05);
      if (!t.empty()) b.draw(c, r, rgb, t);
    }
    for (size_t k = 0; k < whole.pixel_count(); ++k) {
      ASSERT_EQ(whole.depth[k], tight.depth[k]) << "case " << it << " pixel " << k;
      ASSERT_EQ(std::memcmp(&whole.rgba[4 * k], &tight.rgba[4 * k], 4), 0) << "case " << it;
      drawn_pixels += whole.depth[k] != kBackgroundDepth;
    }
  }
  EXPECT_GT(drawn_pixels, 10000);
}

TEST(CpuSphereRaster, TilesDrawWhatPixelByPixelDraws) {
  // Spheres of a fraction of a pixel to ~15 px, many at the frame's right and bottom edges and in
  // its last rows (where a tile passes the frame's end), some coincident with another of a
  // different color (depth ties), some see-through, under the default and a custom light, on
  // frames narrower than a tile too. Frame A draws each over its tight rectangle (tiles of 4 or 8
  // px, vector depth tests); frame B draws each pixel of that rectangle on its own (the
  // one-by-one path), in the same order: every depth and color must agree bit for bit.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const uint8_t bg[4] = {0, 0, 0, 255};
  Lighting custom;
  custom.direction = {-0.4, 0.6, 0.7}, custom.specular = 0.6, custom.shininess = 12.0;
  int64_t drawn_pixels = 0, ties = 0;
  const int sizes[][2] = {{5, 7}, {7, 30}, {13, 9}, {64, 64}, {61, 37}, {203, 117}, {96, 150}};
  int it = 0;
  for (const auto &size : sizes)
    for (int variant = 0; variant < 4; ++variant, ++it) {
      const int w = size[0], h = size[1];
      ViewGeometry g;
      ASSERT_OK(box_view(w, h, variant == 3, 0.0, &g));
      Frame tiles, pixels;
      CpuSphereRaster::clear_target(g, bg, &tiles);
      CpuSphereRaster::clear_target(g, bg, &pixels);
      CpuSphereRaster a, b;
      a.begin_strip(g, &tiles, 0, w - 1);
      b.begin_strip(g, &pixels, 0, w - 1);
      if (variant == 1) a.set_lighting(custom), b.set_lighting(custom);
      const double units = 10.0 / std::max(w, h);  // about a pixel, in world units
      glm::dvec3 last(0.0);
      double last_r = 1.0;
      for (uint32_t i = 0; i < 150; ++i) {
        // Centres near the frame's last row and column half of the time, anywhere otherwise.
        glm::dvec3 p(12 * u(rng) - 6, 12 * u(rng) - 6, 12 * u(rng) - 6);
        const glm::dvec3 q = g.to_view(p);
        double r = units * (0.3 + std::pow(u(rng), 2) * 8.0);
        glm::dvec3 c = q;
        if (i % 2 == 0) {
          // The view-space point that projects near pixel (w - 1 - e, h - 1 - e) at depth -q.z.
          const double ex = u(rng) * 6.0, ey = u(rng) * 6.0;
          const double rx = g.ray_x(int(w - 1 - ex)), ry = g.ray_y(int(h - 1 - ey));
          c = g.orthographic ? glm::dvec3(rx, ry, q.z) : glm::dvec3(-q.z * rx, -q.z * ry, q.z);
        }
        if (i % 7 == 3) c = last, r = last_r;  // a tie with the sphere before
        last = c, last_r = r;
        const uint8_t rgb[3] = {uint8_t(40 + i), uint8_t(200 - i), uint8_t(i * 37)};
        const uint8_t alpha = i % 5 == 4 ? uint8_t(90 + i % 100) : uint8_t(255);
        const PixelRect t = g.sphere_rect_tight(c, r, 0.05);
        if (t.empty()) continue;
        a.draw(c, r, rgb, t, alpha);
        for (int y = t.y0; y <= t.y1; ++y)
          for (int x = t.x0; x <= t.x1; ++x) b.draw(c, r, rgb, PixelRect{x, y, x, y}, alpha);
        ties += i % 7 == 3;
      }
      for (size_t k = 0; k < tiles.pixel_count(); ++k) {
        ASSERT_EQ(tiles.depth[k], pixels.depth[k]) << "case " << it << " pixel " << k;
        ASSERT_EQ(std::memcmp(&tiles.rgba[4 * k], &pixels.rgba[4 * k], 4), 0)
            << "case " << it << " pixel " << k;
        drawn_pixels += tiles.depth[k] != kBackgroundDepth;
      }
    }
  std::printf("tiles against pixels: %lld pixels drawn, %lld ties\n", (long long)drawn_pixels,
              (long long)ties);
  EXPECT_GT(drawn_pixels, 5000);
  EXPECT_GT(ties, 200);
}

TEST(CpuSphereRaster, StripsWriteOnlyTheirColumnsAndTogetherDrawTheWholeFrame) {
  // Two rasters on column strips split at a column no tile is aligned to, drawing the same
  // spheres (many across the split) into one frame, against one raster over every column: the
  // frames must agree bit for bit. A third raster draws the spheres into the left strip alone:
  // no pixel right of the split may change. (Tile rows are written whole, with the pixels not
  // won rewritten as they were, only where the row lies inside the strip: drawn one after the
  // other, as here, a rewrite past the strip's end would not show; two threads could lose a
  // pixel.)
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const uint8_t bg[4] = {10, 20, 30, 255};
  int64_t drawn_pixels = 0;
  for (int variant = 0; variant < 4; ++variant) {
    const int w = 150 + 7 * variant, h = 90, split = 61 + 3 * variant;
    ViewGeometry g;
    ASSERT_OK(box_view(w, h, variant == 3, 0.0, &g));
    Frame whole, strips, left_only;
    CpuSphereRaster::clear_target(g, bg, &whole);
    CpuSphereRaster::clear_target(g, bg, &strips);
    CpuSphereRaster::clear_target(g, bg, &left_only);
    CpuSphereRaster one, left, right, alone;
    one.begin_strip(g, &whole, 0, w - 1);
    left.begin_strip(g, &strips, 0, split - 1);
    right.begin_strip(g, &strips, split, w - 1);
    alone.begin_strip(g, &left_only, 0, split - 1);
    const double units = 10.0 / w;  // about a pixel, in world units
    for (uint32_t i = 0; i < 300; ++i) {
      const glm::dvec3 q = g.to_view(glm::dvec3(12 * u(rng) - 6, 12 * u(rng) - 6, 12 * u(rng) - 6));
      glm::dvec3 c = q;
      if (i % 2 == 0) {  // centred within a few pixels of the split
        const double rx = g.ray_x(split - 4 + int(u(rng) * 8)), ry = g.ray_y(int(u(rng) * h));
        c = g.orthographic ? glm::dvec3(rx, ry, q.z) : glm::dvec3(-q.z * rx, -q.z * ry, q.z);
      }
      const double r = units * (0.5 + std::pow(u(rng), 2) * 6.0);
      const uint8_t rgb[3] = {uint8_t(40 + i), uint8_t(200 - i), uint8_t(i * 37)};
      const PixelRect t = g.sphere_rect_tight(c, r, 0.05);
      if (t.empty()) continue;
      one.draw(c, r, rgb, t);
      left.draw(c, r, rgb, t);
      right.draw(c, r, rgb, t);
      alone.draw(c, r, rgb, t);
    }
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t k = size_t(y) * size_t(w) + size_t(x);
        ASSERT_EQ(whole.depth[k], strips.depth[k]) << "variant " << variant << " pixel " << k;
        ASSERT_EQ(std::memcmp(&whole.rgba[4 * k], &strips.rgba[4 * k], 4), 0)
            << "variant " << variant << " pixel " << k;
        const Frame &expect = x < split ? whole : strips;  // right of the split: untouched
        const float depth = x < split ? expect.depth[k] : kBackgroundDepth;
        ASSERT_EQ(left_only.depth[k], depth) << "variant " << variant << " pixel " << k;
        if (x >= split)
          ASSERT_EQ(std::memcmp(&left_only.rgba[4 * k], bg, 4), 0) << "variant " << variant;
        else
          ASSERT_EQ(std::memcmp(&left_only.rgba[4 * k], &whole.rgba[4 * k], 4), 0);
        drawn_pixels += whole.depth[k] != kBackgroundDepth;
      }
  }
  EXPECT_GT(drawn_pixels, 2000);
}

TEST(CpuSphereRaster, TouchedHoldsEveryPixelAnyPrimitiveWrote) {
  // One primitive at a time on a cleared frame - spheres of a pixel or less (cast one by one),
  // of a small tile and of many tiles, half-bonds in front of the eye and reaching behind it,
  // both projections - and every pixel that changed lies within touched(), which compositing's
  // scan then trusts (Frame::drawn_within).
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const uint8_t bg[4] = {10, 20, 30, 255};
  int drew[2] = {0, 0};
  for (int variant = 0; variant < 2; ++variant) {
    const int w = 120, h = 90;
    ViewGeometry g;
    ASSERT_OK(box_view(w, h, variant == 1, 0.0, &g));
    const double units = 10.0 / w;  // about a pixel, in world units
    for (int i = 0; i < 400; ++i) {
      Frame frame;
      CpuSphereRaster::clear_target(g, bg, &frame);
      CpuSphereRaster raster;
      raster.begin_strip(g, &frame, 0, w - 1);
      const auto at = [&] {
        return g.to_view(glm::dvec3(12 * u(rng) - 6, 12 * u(rng) - 6, 12 * u(rng) - 6));
      };
      const uint8_t rgb[3] = {200, uint8_t(i), 40};
      const glm::dvec3 c = at();
      if (i % 2 == 0) {
        const double r = units * std::pow(10.0, 2.0 * u(rng) - 0.7);  // 0.2 to 20 pixels
        const PixelRect t = g.sphere_rect_tight(c, r, 0.05);
        if (t.empty()) continue;
        drew[0] += raster.draw(c, r, rgb, t);
      } else {
        glm::dvec3 b = c + glm::dvec3(units * 30 * (u(rng) - 0.5), units * 30 * (u(rng) - 0.5),
                                      units * 30 * (u(rng) - 0.5));
        if (i % 6 == 1 && !g.orthographic) b.z = 1.0;  // behind the eye: the double cast
        const double r = units * (0.3 + 3 * u(rng));
        double nearest;
        const PixelRect t = cylinder_rect(g, c, b, r, &nearest);
        if (t.empty()) continue;
        drew[1] += raster.draw_bond(c, b, r, rgb, t);
      }
      const PixelRect &touched = raster.touched();
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const size_t k = frame.index(x, y);
          if (frame.depth[k] == kBackgroundDepth && !std::memcmp(&frame.rgba[4 * k], bg, 4))
            continue;
          ASSERT_TRUE(x >= touched.x0 && x <= touched.x1 && y >= touched.y0 && y <= touched.y1)
              << "variant " << variant << " primitive " << i << " pixel " << x << ", " << y;
        }
    }
  }
  EXPECT_GT(drew[0], 100);
  EXPECT_GT(drew[1], 50);
}

}  // namespace
}  // namespace lantern
