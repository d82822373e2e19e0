// The nine-spheres rule (the nine-spheres paper, §3.2) on its auxiliary grid, and through the
// culler with the conference version's equivalent radius against brute force.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/config/enum_names.h"
#include "core/culling/cull_stage.h"
#include "core/culling/nine_spheres.h"
#include "core/pipeline/scene_settings.h"
#include "core/render/cpu_sphere_raster.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

TEST(NineSpheres, CullsASphereBehindAFullBlockOfNearerEqualSpheres) {
  NineSpheresGrid grid;
  grid.reset(16, 16);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) EXPECT_FALSE(grid.test_and_record(8 + dx, 8 + dy, 1.0f, 0.5f));
  EXPECT_TRUE(grid.test_and_record(8, 8, 2.0f, 0.5f));   // behind, same radius: hidden
  EXPECT_TRUE(grid.test_and_record(8, 8, 1.0f, 0.5f));   // equal depth counts as nearer (D <= d)
  EXPECT_FALSE(grid.test_and_record(8, 8, 2.0f, 0.6f));  // larger than the occluders: drawn
}

TEST(NineSpheres, KeepsTheSphereWhenOneNeighbourIsMissing) {
  for (int missing = 0; missing < 9; ++missing) {
    if (missing == 4) continue;  // the centre pixel itself: it then is unoccupied, drawn anyway
    NineSpheresGrid grid;
    grid.reset(16, 16);
    int k = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx, ++k)
        if (k != missing) grid.test_and_record(8 + dx, 8 + dy, 1.0f, 0.5f);
    EXPECT_FALSE(grid.test_and_record(8, 8, 2.0f, 0.5f)) << "missing neighbour " << missing;
  }
}

TEST(NineSpheres, KeepsTheSphereWhenANeighbourIsFarther) {
  NineSpheresGrid grid;
  grid.reset(16, 16);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      grid.test_and_record(8 + dx, 8 + dy, dx == 1 && dy == 1 ? 3.0f : 1.0f, 0.5f);
  EXPECT_FALSE(grid.test_and_record(8, 8, 2.0f, 0.5f));
}

TEST(NineSpheres, ImageBorderPixelsAreNeverHidden) {
  NineSpheresGrid grid;
  grid.reset(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) grid.test_and_record(x, y, 1.0f, 1.0f);
  EXPECT_FALSE(grid.test_and_record(0, 2, 5.0f, 0.1f));  // only 5 neighbours exist
  EXPECT_TRUE(grid.test_and_record(1, 2, 5.0f, 0.1f));
}

// The equivalent radius of the nine-spheres paper's conference version in the setting of the
// nine-circles covering theorem: spheres of equal projected size (radius proportional to depth, so
// a nearer occluder is smaller in world units and the world-radius rule never lets it hide
// anything), larger than a pixel, whose nine occluders lie wholly in front of the sphere they hide.
// Every culled sphere must be one that brute force (the CPU raster of every sphere, its per-pixel
// owner) does not show.
//
// Projected radii stay in [1, 1.4] px: the theorem counts a pixel as covered when a circle
// overlaps any of its area, while the renderers sample pixel centres; below 1.5 px every centre
// the hidden circle covers lies in the 3x3 block and within 0.71 px of that pixel's occluder, so
// the theorem carries over to centre sampling. (Above 1.5 px a centre two pixels away can be
// covered by the hidden circle alone: the rule is approximate there, as lantern-bench measures.)
class NineSpheresEquivalentRadius : public ::testing::Test {
 protected:
  static constexpr int kCell = 12, kCells = 12, kSize = kCell * kCells;
  enum Kind { kTheorem, kLarger, kMissingOccluder, kOccluderBehind };

  void SetUp() override {
    CameraConfig cfg;  // eye at the origin looking down -z: world coordinates are view space
    cfg.position = std::array<double, 3>{0, 0, 0};
    cfg.look_at = {0, 0, -1};
    cfg.up = {0, 1, 0};
    cfg.fov_y = 20;
    cfg.near_plane = 1.0;
    cfg.far_plane = 200.0;
    ASSERT_OK(make_camera(cfg, {-20, -20, -100}, {20, 20, -1}, 0.0, kSize, kSize, &camera_));
    g_ = ViewGeometry::from_camera(camera_, 200.0);
  }

  // A sphere whose centre projects to (px, py) (pixels, from the top left) at depth d with a
  // projected radius of rpx pixels.
  void add(double px, double py, double d, double rpx) {
    xyz_.insert(xyz_.end(),
                {(2.0 * px / kSize - 1.0) * d / g_.sx, (1.0 - 2.0 * py / kSize) * d / g_.sy, -d});
    radius_.push_back(rpx / g_.pixels_per_unit(d));
    type_.push_back(int32_t(type_.size() % 5));
  }

  ParticleArrays arrays() const {
    ParticleDescription p{};
    p.count = int64_t(type_.size());
    p.position = {xyz_.data(), DataType::kFloat64, 0};
    p.radius = {radius_.data(), DataType::kFloat64, 0};
    p.type = {type_.data(), DataType::kInt32, 0};
    ParticleArrays a;
    EXPECT_OK(ParticleArrays::validate(p, &a));
    return a;
  }

  // One cluster per cell: nine occluders on the 3x3 block and the sphere under test (returned)
  // behind its centre pixel, the hypotheses of the theorem broken as `kind` says: the sphere
  // under test three times as large on screen (it shows around the block), one occluder left
  // out, or the centre pixel's occluder behind the sphere under test.
  int64_t add_cluster(int cx, int cy, Kind kind, std::mt19937 *rng) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const auto in_pixel = [&] { return 0.02 + 0.96 * u(*rng); };
    const double rpx = 1.0 + 0.4 * u(*rng);
    const int bx = cx * kCell + 4, by = cy * kCell + 4;  // clusters never overlap
    const int missing = kind == kMissingOccluder ? int(u(*rng) * 9) : -1;
    const int behind = kind == kOccluderBehind ? 4 : -1;  // the centre pixel's occluder
    for (int k = 0; k < 9; ++k) {
      if (k == missing) continue;
      add(bx + k % 3 + in_pixel(), by + k / 3 + in_pixel(),
          k == behind ? 80.0 : 10.0 + 10 * u(*rng), rpx);
    }
    add(bx + 1 + in_pixel(), by + 1 + in_pixel(), 40.0 + 20 * u(*rng),
        kind == kLarger ? 3.0 * rpx : rpx);
    return int64_t(type_.size()) - 1;
  }

  // Which particles the culler leaves out in `mode` with `rule`.
  std::vector<bool> culled(OcclusionMode mode, NineSpheresRadius rule) const {
    const ParticleArrays p = arrays();
    SceneConfig s;
    s.width = s.height = kSize;
    s.per_particle_radius = true;
    s.culling.occlusion = mode;
    s.culling.nine_spheres_radius = rule;
    Culler culler;
    DrawList draw;
    culler.run(p, build_bricks(p, BrickOptions{}), camera_, cull_settings(s), radius_rule(s, p),
               &draw);
    EXPECT_FALSE(draw.everything);
    std::vector<bool> out(type_.size(), true);
    for (const uint64_t e : draw.spheres) out[entry_index(e)] = false;
    return out;
  }

  // Which particles own at least one pixel when every sphere is drawn: sphere i is shown if,
  // drawn last over all the others, it wins a pixel (the raster keeps no per-pixel owner).
  std::vector<bool> shown_by_brute_force() const {
    const uint8_t bg[4] = {0, 0, 0, 255}, rgb[3] = {200, 200, 200};
    const auto centre = [&](size_t i) {
      return glm::dvec3{xyz_[3 * i], xyz_[3 * i + 1], xyz_[3 * i + 2]};
    };
    const auto rect = [&](size_t i) { return g_.sphere_rect_tight(centre(i), radius_[i], 0.05); };
    std::vector<bool> shown(type_.size(), false);
    Frame frame;
    CpuSphereRaster raster;
    for (size_t last = 0; last < type_.size(); ++last) {
      CpuSphereRaster::clear_target(g_, bg, &frame);
      raster.begin_strip(g_, &frame, 0, kSize - 1);
      for (size_t i = 0; i < type_.size(); ++i)
        if (i != last) raster.draw(centre(i), radius_[i], rgb, rect(i));
      shown[last] = raster.draw(centre(last), radius_[last], rgb, rect(last));
    }
    return shown;
  }

  Camera camera_;
  ViewGeometry g_;
  std::vector<double> xyz_, radius_;
  std::vector<int32_t> type_;
};

TEST_F(NineSpheresEquivalentRadius, NeverCullsWhatBruteForceShowsAndCullsWhatTheTheoremHides) {
  std::mt19937 rng(3);
  std::vector<std::pair<int64_t, Kind>> tested;
  for (int cy = 0; cy < kCells; ++cy)
    for (int cx = 0; cx < kCells; ++cx) {
      const Kind kind = Kind(rng() % 4);
      tested.push_back({add_cluster(cx, cy, kind, &rng), kind});
    }
  const std::vector<bool> shown = shown_by_brute_force();
  const std::vector<bool> world =
      culled(OcclusionMode::kNineSpheresSorted, NineSpheresRadius::kWorld);
  int64_t theorem_cases = 0, shown_cases = 0;
  for (const auto &[i, kind] : tested) {
    theorem_cases += kind == kTheorem;
    shown_cases += shown[i];
    if (kind == kTheorem) EXPECT_FALSE(shown[i]) << "the theorem's setting hides sphere " << i;
    EXPECT_FALSE(world[i]) << "world radius: nearer occluders are smaller, sphere " << i;
  }
  std::printf("%lld spheres under test in the theorem's setting, %lld shown by brute force\n",
              static_cast<long long>(theorem_cases), static_cast<long long>(shown_cases));
  ASSERT_GT(theorem_cases, 20);
  ASSERT_GT(shown_cases, 20);  // the checks below can fail: many spheres under test do show
  for (const OcclusionMode mode :
       {OcclusionMode::kNineSpheres, OcclusionMode::kNineSpheresSorted}) {
    const std::vector<bool> hidden = culled(mode, NineSpheresRadius::kEquivalent);
    for (size_t i = 0; i < shown.size(); ++i)
      EXPECT_FALSE(hidden[i] && shown[i]) << name_of(mode) << ": culled visible sphere " << i;
    for (const auto &[i, kind] : tested)
      EXPECT_EQ(hidden[i], kind == kTheorem)
          << name_of(mode) << ": sphere " << i << " kind " << kind;
  }
}

}  // namespace
}  // namespace lantern
