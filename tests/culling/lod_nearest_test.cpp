// lod.select: nearest: an opaque brick keeps its `keep` particles nearest the
// camera at their own radius. On a dense block seen face-on the dropped ones are exactly the
// hidden ones, so the image is bit-identical to the full render (the uniform prefix at the same
// fraction is not); keeping everything changes nothing; the selection is deterministic and keeps
// exactly `keep` particles per brick, the nearest by (front depth, brick slot).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <set>
#include <utility>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/culling/brick_selection.h"
#include "core/culling/cull_pass.h"
#include "core/culling/cull_stage.h"
#include "core/pipeline/rank_draw.h"
#include "core/pipeline/scene_settings.h"
#include "tests/support/bricked_particles.h"

namespace lantern {
namespace {

// A simple cubic block of n^3 sites, radius 0.75. At spacing 1 neighbouring spheres overlap enough
// (0.75 > sqrt(2) / 2) that a layer seen along an axis covers every pixel of its face, and a
// sphere one layer back is 1 deeper everywhere it projects, so only the front layer shows.
struct Block : testing::BrickedParticles {
  int n;
  double spacing;
  explicit Block(int n_, double spacing_ = 1.0) : n(n_), spacing(spacing_) {
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          xyz.insert(xyz.end(), {x * spacing, y * spacing, z * spacing});
          type.push_back((x + 2 * y + 3 * z) % 5);
        }
    finish();
  }
};

constexpr double kRadius = 0.75;

SceneConfig scene_of(double fraction, LodSelect select, bool face_on) {
  SceneConfig s;
  s.width = s.height = 160;
  s.radius = kRadius;
  s.renderer = RendererChoice::kCpu;
  s.culling.occlusion = OcclusionMode::kHzb;
  s.lod.fraction = fraction;
  s.lod.select = select;
  if (face_on) {  // orthographic, looking down -z at the z = n - 1 face
    s.camera.projection = Projection::kOrthographic;
    s.camera.position = std::array<double, 3>{15.5, 15.5, 100.0};
    s.camera.look_at = {15.5, 15.5, 15.5};
    s.camera.up = {0, 1, 0};
  }
  return s;
}

Camera camera_for(const Block &b, const SceneConfig &s) {
  Camera cam;
  const double hi = (b.n - 1) * b.spacing;
  EXPECT_TRUE(
      make_camera(s.camera, {0, 0, 0}, {hi, hi, hi}, kRadius, s.width, s.height, &cam).ok());
  return cam;
}

struct Render {
  Frame frame;
  CullStats stats;
  BrickSelection sel;
};

Render render(const Block &b, const SceneConfig &s) {
  const Camera cam = camera_for(b, s);
  Render r;
  RankDrawScratch scratch;
  RankDraw drawn;
  EXPECT_TRUE(
      draw_scene_on_rank(RankScene(b.arrays, b.bricks, cam, s), &scratch, &r.frame, &drawn).ok());
  r.stats = drawn.cull;
  r.sel = scratch.selection;
  return r;
}

bool same(const Frame &a, const Frame &b) {
  return a.rgba == b.rgba && a.depth.size() == b.depth.size() &&
         std::memcmp(a.depth.data(), b.depth.data(), 4 * a.depth.size()) == 0;
}

int64_t nearest_bricks(const BrickSelection &sel) {
  return std::count_if(sel.visible.begin(), sel.visible.end(),
                       [](const VisibleBrick &v) { return v.nearest; });
}

int64_t differing_pixels(const Frame &a, const Frame &b) {
  int64_t n = 0;
  for (size_t p = 0; p < a.pixel_count(); ++p)
    n += std::memcmp(&a.rgba[4 * p], &b.rgba[4 * p], 4) != 0;
  return n;
}

TEST(LodNearest, FaceOnBlockDropsOnlyHiddenParticles) {
  const Block block(32);  // bricks of 512 sites, 8 layers deep
  const int64_t n = int64_t(block.type.size());
  const Render full = render(block, scene_of(1.0, LodSelect::kUniform, true));
  const Render nearest = render(block, scene_of(0.1, LodSelect::kNearest, true));
  const Render uniform = render(block, scene_of(0.1, LodSelect::kUniform, true));
  // The budget goes to the front bricks (the ones behind are expected hidden), which keep
  // under all of their particles but more than their front layer (an eighth): everything dropped
  // is hidden, so the same bytes.
  ASSERT_GT(nearest_bricks(nearest.sel), 0);
  for (const VisibleBrick &v : nearest.sel.visible)
    if (v.nearest && v.keep > 8) EXPECT_GE(v.keep, block.bricks.bricks[v.brick].count / 8);
  EXPECT_GE(nearest.stats.lod_dropped, n * 85 / 100);
  EXPECT_TRUE(same(full.frame, nearest.frame));
  // The uniform prefix at the same fraction keeps spheres from every layer and grows them.
  EXPECT_EQ(nearest_bricks(uniform.sel), 0);
  EXPECT_GE(uniform.stats.lod_dropped, n * 85 / 100);
  EXPECT_FALSE(same(full.frame, uniform.frame));
}

TEST(LodNearest, KeepingEverythingIsBitIdenticalToNoLod) {
  const Block block(24);
  for (const bool face_on : {false, true}) {
    const Render plain = render(block, scene_of(1.0, LodSelect::kUniform, face_on));
    SceneConfig budget_all = scene_of(1.0, LodSelect::kNearest, face_on);
    budget_all.lod.budget = int64_t(block.type.size());  // runs the LOD code, keeping all
    const Render fraction_one = render(block, scene_of(1.0, LodSelect::kNearest, face_on));
    const Render all = render(block, budget_all);
    EXPECT_TRUE(same(plain.frame, fraction_one.frame));
    EXPECT_TRUE(same(plain.frame, all.frame));
    EXPECT_EQ(all.stats.lod_dropped, 0);
    EXPECT_EQ(nearest_bricks(all.sel), 0);
  }
}

// The particles each brick should keep, computed by a full sort: (float front depth, slot).
std::set<uint32_t> expected_nearest(const Block &b, const BrickSelection &sel,
                                    const VisibleBrick &v) {
  const Brick &brick = b.bricks.bricks[v.brick];
  std::vector<std::pair<float, uint32_t>> keyed;
  for (uint32_t k = 0; k < brick.count; ++k) {
    const uint32_t i = b.bricks.order[brick.first + k];
    const glm::dvec3 p{b.xyz[3 * i], b.xyz[3 * i + 1], b.xyz[3 * i + 2]};
    keyed.push_back({float(-sel.g.to_view(p).z - kRadius), k});
  }
  std::sort(keyed.begin(), keyed.end());
  std::set<uint32_t> kept;
  for (uint32_t k = 0; k < v.keep; ++k) kept.insert(b.bricks.order[brick.first + keyed[k].second]);
  return kept;
}

TEST(LodNearest, KeepsExactlyTheNearestKeepOfEachBrickDeterministically) {
  // Face-on, orthographic: the front cells (2 radii wide, wider than the lattice spacing) each
  // hold a front-layer centre, so the front particles are front-layer ones and the rest follow
  // by depth: each brick keeps exactly its `keep` nearest by (front depth, slot).
  const Block block(24);
  SceneConfig s = scene_of(0.5, LodSelect::kNearest, true);
  s.culling.occlusion = OcclusionMode::kNone;  // draws every kept particle: the selection itself
  const Camera cam = camera_for(block, s);
  const RadiusRule radius = radius_rule(s, block.arrays);
  BrickSelection sel;
  const CullSettings cull = cull_settings(s);
  select_bricks(block.bricks, cam, cull, radius, &sel);
  ASSERT_GT(nearest_bricks(sel), 0);
  Culler culler;
  DrawList first, second;
  const CullStats st = culler.cull(block.arrays, block.bricks, cull, sel, &first);
  culler.cull(block.arrays, block.bricks, cull, sel, &second);
  EXPECT_EQ(first.spheres, second.spheres);

  std::set<uint32_t> drawn;
  for (const uint64_t e : first.spheres) drawn.insert(entry_index(e));
  EXPECT_EQ(drawn.size(), first.spheres.size());
  int64_t kept = 0;
  for (const VisibleBrick &v : sel.visible) {
    kept += v.keep;
    const Brick &brick = block.bricks.bricks[v.brick];
    std::set<uint32_t> in_brick;
    for (uint32_t k = 0; k < brick.count; ++k) {
      const uint32_t i = block.bricks.order[brick.first + k];
      if (drawn.count(i)) in_brick.insert(i);
    }
    EXPECT_EQ(in_brick.size(), v.keep) << "brick " << v.brick;
    if (v.nearest) EXPECT_EQ(in_brick, expected_nearest(block, sel, v)) << "brick " << v.brick;
  }
  EXPECT_EQ(st.frustum_culled, 0);
  EXPECT_EQ(st.drawn, kept);
  EXPECT_EQ(st.lod_dropped, int64_t(block.type.size()) - kept);
  // Every brick is opaque: all kept spheres are drawn at their own radius (the prefix would grow).
  for (const uint64_t e : first.spheres) ASSERT_EQ(entry_scale(e), 1.0f);
}

TEST(LodNearest, ObliqueBlockKeepsItsPicture) {
  // The default perspective camera sees three faces of the block, each oblique: a brick's
  // visible particles span its whole depth range, so its front is found per screen sample, not
  // as a depth slab. At 160 px one thread walks the bricks; at 320 px two column strips do, each
  // picking fronts against its own depth pyramid.
  const Block block(32);
  for (const int width : {160, 320}) {
    SCOPED_TRACE(width);
    SceneConfig full_s = scene_of(1.0, LodSelect::kUniform, false);
    SceneConfig nearest_s = scene_of(0.25, LodSelect::kNearest, false);
    SceneConfig uniform_s = scene_of(0.25, LodSelect::kUniform, false);
    for (SceneConfig *s : {&full_s, &nearest_s, &uniform_s}) s->width = s->height = width;
    const Render full = render(block, full_s);
    const Render nearest = render(block, nearest_s);
    const Render uniform = render(block, uniform_s);
    const int64_t pixels = int64_t(full.frame.pixel_count());
    const int64_t nd = differing_pixels(full.frame, nearest.frame);
    const int64_t ud = differing_pixels(full.frame, uniform.frame);
    // Measured: 346 and 12958 of 25600; 1100 and 51852 of 102400. The nearest image differs
    // where an edge or corner brick shows more than its share (it keeps its nearest front
    // particles) and at silhouettes.
    std::cout << width << " px, differing pixels: nearest " << nd << ", uniform " << ud << " of "
              << pixels << "\n";
    EXPECT_LT(nd, pixels / 25) << nd << " of " << pixels;
    EXPECT_GT(ud, pixels / 4) << ud << " of " << pixels;
  }
}

}  // namespace
}  // namespace lantern
