// Opaque-sphere level of detail keeps what a brick covers on screen: a sparse cloud of sub-pixel
// spheres drawn at 25 % covers as many pixels as the full cloud (kept spheres grow by the square
// root of n / keep, so their discs hold the area of the spheres they stand for), while bricks of
// spheres of a pixel or more keep the cube-root growth of their silhouettes, and density keeps its
// own (cube-root) footprints.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/culling/brick_selection.h"
#include "core/pipeline/rank_draw.h"
#include "core/pipeline/scene_settings.h"
#include "tests/support/bricked_particles.h"

namespace lantern {
namespace {

// `n` particles uniform in a cube of side `side` (fixed seed), radius 0.5 (the scene default).
struct Cloud : testing::BrickedParticles {
  double side;
  Cloud(int n, double side_) : side(side_) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, side);
    for (int i = 0; i < n; ++i) {
      xyz.insert(xyz.end(), {u(rng), u(rng), u(rng)});
      type.push_back(i % 3);
    }
    finish();
  }
  Camera camera(const SceneConfig &s) const {
    Camera cam;
    EXPECT_TRUE(
        make_camera(s.camera, {0, 0, 0}, {side, side, side}, 0.5, s.width, s.height, &cam).ok());
    return cam;
  }
};

SceneConfig scene(double fraction, SceneStyle style = SceneStyle::kSpheres) {
  SceneConfig s;
  s.width = s.height = 256;
  s.style = style;
  s.culling.occlusion = OcclusionMode::kHzb;
  s.renderer = RendererChoice::kCpu;
  s.lod.fraction = fraction;
  return s;
}

// Pixels the CPU raster (with hzb) covers, i.e. not left at the background.
int64_t covered_pixels(const Cloud &c, const SceneConfig &s) {
  const Camera cam = c.camera(s);
  RankDrawScratch scratch;
  Frame frame;
  RankDraw drawn;
  EXPECT_TRUE(
      draw_scene_on_rank(RankScene(c.arrays, c.bricks, cam, s), &scratch, &frame, &drawn).ok());
  int64_t covered = 0;
  for (size_t p = 0; p < frame.pixel_count(); ++p) covered += frame.depth[p] < kBackgroundDepth;
  return covered;
}

TEST(LodCoverage, SubPixelCloudKeepsItsCoveredPixelsAtAQuarter) {
  const Cloud cloud(40000, 200.0);  // spheres of about 0.35 px radius, a few % overlapping
  const int64_t full = covered_pixels(cloud, scene(1.0));
  const int64_t quarter = covered_pixels(cloud, scene(0.25));
  ASSERT_GT(full, 10000);
  // Cube-root growth would cover about (1/4)^(1/3) = 63 % of them; the square root keeps them
  // within the sample's noise (a few %).
  EXPECT_NEAR(double(quarter) / double(full), 1.0, 0.08) << full << " vs " << quarter;
}

TEST(LodCoverage, GrowthBySquareRootOnlyForSubPixelOpaqueBricks) {
  const Cloud far_cloud(40000, 200.0), near_cloud(40000, 40.0);  // ~0.35 px and ~2 px spheres
  const auto growths = [](const Cloud &c, const SceneConfig &s) {
    BrickSelection sel;
    select_bricks(c.bricks, c.camera(s), cull_settings(s), radius_rule(s, c.arrays), &sel);
    std::vector<double> expected_exponent;  // log(scale) / log(n / keep) per reduced brick
    for (const VisibleBrick &v : sel.visible) {
      const double ratio = double(c.bricks.bricks[v.brick].count) / double(v.keep);
      if (ratio > 1.5) expected_exponent.push_back(std::log(v.radius_scale) / std::log(ratio));
    }
    return expected_exponent;
  };
  const auto all_near = [](const std::vector<double> &e, double want) {
    if (e.empty()) return false;
    for (const double x : e)
      if (std::abs(x - want) > 1e-4) return false;
    return true;
  };
  EXPECT_TRUE(all_near(growths(far_cloud, scene(0.25)), 0.5));
  EXPECT_TRUE(all_near(growths(near_cloud, scene(0.25)), 1.0 / 3.0));
  EXPECT_TRUE(all_near(growths(far_cloud, scene(0.25, SceneStyle::kDensity)), 1.0 / 3.0));
}

}  // namespace
}  // namespace lantern
