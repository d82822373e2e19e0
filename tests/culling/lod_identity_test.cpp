// Level of detail that keeps everything changes nothing: `lod` with fraction 1, or a budget at
// least the particle count (which runs the LOD code: every brick keeps all of its particles), gives
// an image bit-identical to no `lod`, for opaque spheres (CPU raster, hzb) and for style: density.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/culling/brick_selection.h"
#include "core/pipeline/rank_draw.h"
#include "core/pipeline/scene_settings.h"
#include "core/render/density_pass.h"
#include "core/render/sphere_instances.h"
#include "tests/support/bricked_particles.h"

namespace lantern {
namespace {

struct Lattice : testing::BrickedParticles {
  Lattice() {
    for (int z = 0; z < 30; ++z)
      for (int y = 0; y < 30; ++y)
        for (int x = 0; x < 30; ++x) {
          xyz.insert(xyz.end(), {x * 1.1, y * 1.1 + 0.05 * (x % 3), z * 1.1});
          type.push_back((x / 5 + y / 5 + z / 5) % 4);
        }
    finish();
  }
};

SceneConfig scene_of(SceneStyle style) {
  SceneConfig s;
  s.width = s.height = 160;
  s.style = style;
  s.culling.occlusion = OcclusionMode::kHzb;
  return s;
}

Camera camera_for(const SceneConfig &s) {
  Camera cam;
  EXPECT_TRUE(
      make_camera(s.camera, {0, 0, 0}, {31.9, 32.0, 31.9}, 0.5, s.width, s.height, &cam).ok());
  return cam;
}

Frame spheres(const Lattice &l, const SceneConfig &s, int64_t *lod_dropped) {
  const Camera cam = camera_for(s);
  RankDrawScratch scratch;
  Frame frame;
  RankDraw drawn;
  EXPECT_TRUE(
      draw_scene_on_rank(RankScene(l.arrays, l.bricks, cam, s), &scratch, &frame, &drawn).ok());
  *lod_dropped = drawn.cull.lod_dropped;
  return frame;
}

std::vector<int64_t> density(const Lattice &l, const SceneConfig &s, int64_t *lod_dropped) {
  const Camera cam = camera_for(s);
  const RadiusRule radius = radius_rule(s, l.arrays);
  const InstanceRecipe recipe = make_recipe(l.arrays, shading_settings(s), radius, cam, Extent{});
  BrickSelection sel;
  select_density_bricks(l.bricks, cam, cull_settings(s), radius, &sel, nullptr);
  DensityImage image;
  *lod_dropped =
      render_density(l.arrays, l.bricks, cull_settings(s), sel, recipe, &image).lod_dropped;
  return {image.sum.begin(), image.sum.end()};
}

bool same(const Frame &a, const Frame &b) {
  return a.rgba == b.rgba && std::memcmp(a.depth.data(), b.depth.data(), 4 * a.depth.size()) == 0;
}

TEST(LodIdentity, KeepingEverythingIsBitIdenticalToNoLod) {
  const Lattice l;
  for (const SceneStyle style : {SceneStyle::kSpheres, SceneStyle::kDensity}) {
    SceneConfig plain = scene_of(style), fraction_one = plain, budget_all = plain, tenth = plain;
    fraction_one.lod.fraction = 1.0;
    budget_all.lod.budget = int64_t(l.type.size());
    tenth.lod.fraction = 0.1;  // the control: a real reduction does change the image
    int64_t d0 = -1, d1 = -1, d2 = -1, d3 = -1;
    if (style == SceneStyle::kSpheres) {
      const Frame ref = spheres(l, plain, &d0);
      EXPECT_TRUE(same(ref, spheres(l, fraction_one, &d1)));
      EXPECT_TRUE(same(ref, spheres(l, budget_all, &d2)));
      EXPECT_FALSE(same(ref, spheres(l, tenth, &d3)));
    } else {
      const std::vector<int64_t> ref = density(l, plain, &d0);
      EXPECT_EQ(ref, density(l, fraction_one, &d1));
      EXPECT_EQ(ref, density(l, budget_all, &d2));
      EXPECT_NE(ref, density(l, tenth, &d3));
    }
    EXPECT_EQ(d0, 0);
    EXPECT_EQ(d1, 0);
    EXPECT_EQ(d2, 0);
    EXPECT_GT(d3, 0);
  }
}

}  // namespace
}  // namespace lantern
