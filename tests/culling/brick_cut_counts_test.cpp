// Cutting planes changed between frames (core/culling/brick_cut_counts.h): after any sequence of
// plane edits the incremental per-brick counts classify every brick exactly as a classification
// from scratch does, a plane edit tests only a share of the bricks, and new bricks start afresh.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/culling/brick_cut_counts.h"
#include "core/culling/brick_selection.h"
#include "core/culling/cut_planes.h"
#include "core/pipeline/scene_settings.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

struct Cloud {
  std::vector<double> xyz;
  ParticleArrays arrays() const {
    ParticleDescription p{};
    p.count = int64_t(xyz.size() / 3);
    p.position = {xyz.data(), DataType::kFloat64, 0};
    ParticleArrays a;
    EXPECT_OK(ParticleArrays::validate(p, &a));
    return a;
  }
};

// A box of uniform particles plus a dense clump, so that bricks come in many sizes.
Cloud cloud(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> box(0.0, 40.0), clump(10.0, 14.0);
  Cloud c;
  for (int i = 0; i < n; ++i) c.xyz.insert(c.xyz.end(), {box(rng), box(rng), box(rng)});
  for (int i = 0; i < n / 4; ++i) c.xyz.insert(c.xyz.end(), {clump(rng), clump(rng), clump(rng)});
  return c;
}

// Index of the first brick whose classification differs from a from-scratch one, or -1.
int64_t first_mismatch(const BrickSet &bricks, const BrickCutCounts &counts,
                       const std::vector<CutPlane> &cuts) {
  const CutPlanes scratch(cuts);
  for (uint32_t i = 0; i < bricks.bricks.size(); ++i) {
    const CutPlanes::Side want =
        scratch.empty() ? CutPlanes::Side::kKept
                        : scratch.classify_box(bricks.bricks[i].lo, bricks.bricks[i].hi);
    if (counts.side(i) != want) return i;
  }
  return -1;
}

// A random plane; half of them axis-aligned through a brick's own bound, where ties between
// "touches" and "crosses" are decided by the last bit.
CutPlane random_plane(const BrickSet &bricks, std::mt19937 *rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0), offset(-30.0, 70.0);
  std::uniform_int_distribution<size_t> brick(0, bricks.bricks.size() - 1);
  std::uniform_int_distribution<int> axis(0, 2), coin(0, 1);
  CutPlane c;
  if (coin(*rng)) {
    const int a = axis(*rng);
    const double sign = coin(*rng) ? 1.0 : -1.0;
    c.normal = {0, 0, 0};
    c.normal[a] = sign;
    const Brick &b = bricks.bricks[brick(*rng)];
    c.offset = sign * (coin(*rng) ? b.lo[a] : b.hi[a]);
  } else {
    do c.normal = {unit(*rng), unit(*rng), unit(*rng)};
    while (c.normal == std::array<double, 3>{0, 0, 0});
    c.offset = offset(*rng);
  }
  return c;
}

TEST(BrickCutCounts, RandomPlaneEditsMatchAClassificationFromScratch) {
  const Cloud c = cloud(60000, 7);
  const BrickSet bricks = build_bricks(c.arrays(), BrickOptions{});
  ASSERT_GT(bricks.bricks.size(), 100u);
  std::mt19937 rng(11);
  std::vector<CutPlane> cuts;
  BrickCutCounts counts;
  counts.update(bricks, cuts);
  EXPECT_TRUE(counts.last_update().from_scratch);
  int64_t tested = 0, edits = 0;
  for (int round = 0; round < 400; ++round) {
    const int what = std::uniform_int_distribution<int>(0, 4)(rng);
    if (what <= 1 || cuts.empty()) {  // add (sometimes a duplicate of a plane already there)
      cuts.push_back(!cuts.empty() && what == 1 ? cuts[rng() % cuts.size()]
                                                : random_plane(bricks, &rng));
    } else if (what == 2) {  // remove
      cuts.erase(cuts.begin() + long(rng() % cuts.size()));
    } else if (what == 3) {  // toggle
      CutPlane &p = cuts[rng() % cuts.size()];
      p.enabled = !p.enabled;
    } else {  // move
      cuts[rng() % cuts.size()].offset += 0.5;
    }
    if (cuts.size() > 6) cuts.erase(cuts.begin());
    counts.update(bricks, cuts);
    ASSERT_FALSE(counts.last_update().from_scratch) << "round " << round;
    ASSERT_LE(counts.last_update().planes_added + counts.last_update().planes_removed, 3)
        << "round " << round;
    ASSERT_EQ(first_mismatch(bricks, counts, cuts), -1) << "round " << round;
    tested += counts.last_update().bricks_tested;
    ++edits;
  }
  // A plane edit tests the bricks near the planes it adds or removes, not every brick twice.
  EXPECT_LT(double(tested) / double(edits), 0.5 * double(bricks.bricks.size()));
}

TEST(BrickCutCounts, AddingThenRemovingAPlaneRestoresEveryCounter) {
  const Cloud c = cloud(20000, 3);
  const BrickSet bricks = build_bricks(c.arrays(), BrickOptions{});
  const std::vector<CutPlane> base = {{{0, 1, 0}, 20.0, true}};
  BrickCutCounts counts;
  counts.update(bricks, base);
  std::vector<CutPlanes::Side> before;
  for (uint32_t i = 0; i < bricks.bricks.size(); ++i) before.push_back(counts.side(i));
  std::vector<CutPlane> more = base;
  more.push_back({{1, 0, 0}, 12.0, true});
  counts.update(bricks, more);
  EXPECT_EQ(counts.last_update().planes_added, 1);
  EXPECT_EQ(counts.last_update().planes_removed, 0);
  EXPECT_EQ(first_mismatch(bricks, counts, more), -1);
  counts.update(bricks, base);
  EXPECT_EQ(counts.last_update().planes_removed, 1);
  for (uint32_t i = 0; i < bricks.bricks.size(); ++i) ASSERT_EQ(counts.side(i), before[i]) << i;
}

TEST(BrickCutCounts, NewBricksStartFromScratch) {
  Cloud c = cloud(20000, 5);
  BrickSet bricks = build_bricks(c.arrays(), BrickOptions{});
  const std::vector<CutPlane> cuts = {{{0, 0, 1}, 18.0, true}, {{1, 1, 0}, 30.0, true}};
  BrickCutCounts counts;
  counts.update(bricks, cuts);
  EXPECT_TRUE(counts.last_update().from_scratch);
  counts.update(bricks, cuts);
  EXPECT_FALSE(counts.last_update().from_scratch);
  EXPECT_EQ(counts.last_update().bricks_tested, 0);
  // The particles move: the refit gives new bounds and a new generation.
  for (double &x : c.xyz) x += 0.3;
  ASSERT_TRUE(refit_bricks(c.arrays(), 4.0, &bricks));
  counts.update(bricks, cuts);
  EXPECT_TRUE(counts.last_update().from_scratch);
  EXPECT_EQ(first_mismatch(bricks, counts, cuts), -1);
}

TEST(BrickCutCounts, SelectionThroughCountsEqualsSelectionFromScratch) {
  const Cloud c = cloud(30000, 9);
  const ParticleArrays p = c.arrays();
  const BrickSet bricks = build_bricks(p, BrickOptions{});
  SceneConfig scene;
  scene.width = 320;
  scene.height = 240;
  scene.camera.zoom = 2.0;  // some bricks outside the frustum
  Camera cam;
  ASSERT_OK(make_camera(scene.camera, bricks.lo, bricks.hi, scene.radius, scene.width, scene.height,
                        &cam));
  BrickCutCounts counts;
  const std::vector<std::vector<CutPlane>> edits = {
      {},
      {{{0, 1, 0}, 20.0, true}},
      {{{0, 1, 0}, 20.0, true}, {{1, 0, 1}, 35.0, true}},
      {{{0, 1, 0}, 20.0, false}, {{1, 0, 1}, 35.0, true}},
      {{{1, 0, 1}, 35.0, true}},
      {}};
  for (size_t e = 0; e < edits.size(); ++e) {
    scene.cuts = edits[e];
    BrickSelection full, incremental;
    select_bricks(bricks, cam, cull_settings(scene), radius_rule(scene, p), &full);
    select_bricks(bricks, cam, cull_settings(scene), radius_rule(scene, p), &incremental, &counts);
    ASSERT_EQ(full.visible.size(), incremental.visible.size()) << "edit " << e;
    for (size_t i = 0; i < full.visible.size(); ++i) {
      ASSERT_EQ(full.visible[i].brick, incremental.visible[i].brick) << "edit " << e;
      ASSERT_EQ(full.visible[i].cut_each, incremental.visible[i].cut_each) << "edit " << e;
    }
    EXPECT_EQ(full.stats.cut_culled, incremental.stats.cut_culled) << "edit " << e;
  }
}

}  // namespace
}  // namespace lantern
