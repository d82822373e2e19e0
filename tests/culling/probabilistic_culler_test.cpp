// Ibrahim et al.'s probabilistic occlusion culling (occlusion: probabilistic): the binomial tail of
// eq. 21 against exact sums, algorithm 1's buffers, determinism, the class-P guarantee, and the
// limit C_occ -> 1 against brute force, all through the CPU sphere pass.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/culling/brick_selection.h"
#include "core/culling/probabilistic/binomial_tail.h"
#include "core/culling/probabilistic/depth_confidence.h"
#include "core/pipeline/rank_draw.h"
#include "core/render/cpu_sphere_pass.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

// Binomial tails: the normal approximation (with continuity correction) agrees with the exact
// sums within 0.01 where binomial_tail uses it (variance >= 9), and binomial_tail is exact below.
TEST(BinomialTail, NormalApproximationMatchesExactSums) {
  const std::array<std::pair<int, double>, 6> cases = {
      {{40, 0.5}, {50, 0.3}, {64, 0.2}, {100, 0.5}, {200, 0.1}, {1000, 0.03}}};
  for (const auto &[n, p] : cases) {
    ASSERT_GE(n * p * (1 - p), kNormalMinVariance);
    double worst = 0.0;
    for (int k = 0; k <= n + 1; ++k) {
      const double exact = binomial_tail_exact(n, p, k);
      worst = std::max(worst, std::abs(binomial_tail_normal(n, p, k) - exact));
      EXPECT_DOUBLE_EQ(binomial_tail(n, p, k), binomial_tail_normal(n, p, k));
    }
    EXPECT_LT(worst, 0.02) << "n " << n << " p " << p;
  }
  // Analytic values: P(X >= 1) = 1 - (1 - p)^n; P(X >= n) = p^n; P(X >= 0) = 1.
  EXPECT_NEAR(binomial_tail_exact(10, 0.2, 1), 1.0 - std::pow(0.8, 10), 1e-12);
  EXPECT_NEAR(binomial_tail_exact(10, 0.2, 10), std::pow(0.2, 10), 1e-18);
  EXPECT_DOUBLE_EQ(binomial_tail_exact(10, 0.2, 0), 1.0);
  EXPECT_DOUBLE_EQ(binomial_tail_exact(10, 0.2, 11), 0.0);
  // Symmetric case: P(X >= 16) for Bin(32, 1/2) is 1/2 + C(32,16)/2^33.
  EXPECT_NEAR(binomial_tail_exact(32, 0.5, 16), 0.5 + 601080390.0 / 8589934592.0, 1e-12);
  // Small variance: the exact sum.
  EXPECT_DOUBLE_EQ(binomial_tail(32, 0.05, 3), binomial_tail_exact(32, 0.05, 3));
}

// The exact tail reads log(j!) from a table up to j = 64 and from std::lgamma beyond: both must
// give the very sum written out with std::lgamma, bit for bit, on either side of the table's end
// (an off-by-one in the table shifts every term and fails here).
TEST(BinomialTail, FactorialTableGivesTheSameBitsAsLgamma) {
  const auto direct = [](int n, double p, int k) {
    const double lp = std::log(p), lq = std::log1p(-p), lgn = std::lgamma(n + 1.0);
    double sum = 0.0;
    for (int j = k; j <= n; ++j)
      sum +=
          std::exp(lgn - std::lgamma(j + 1.0) - std::lgamma(n - j + 1.0) + j * lp + (n - j) * lq);
    return std::min(sum, 1.0);
  };
  for (const int n : {1, 7, 32, 63, 64, 65, 90})
    for (const double p : {0.01, 0.2, 0.5, 0.93})
      for (const int k : {1, 2, n / 3 + 1, n / 2 + 1, n})
        EXPECT_EQ(binomial_tail_exact(n, p, k), direct(n, p, k)) << n << " " << p << " " << k;
}

// The cull buffer's pyramid test: a box fails only where every texel over it is nearer than the
// box, and then reports the mean confidence of those texels; one texel as far as the box passes.
TEST(DepthConfidence, PyramidFailsOnlyWhenEveryTexelIsNearer) {
  const int w = 8, h = 4;
  std::vector<ConfidencePixel> px(size_t(w) * h, ConfidencePixel::empty());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      ConfidencePixel &p = px[size_t(y) * w + x];
      p.d_cull = 2.0f + 0.125f * float(x), p.c_cull = 0.25f * float(y + 1);
    }
  ConfidencePyramid pyramid;
  pyramid.build(px, w, h);
  const PixelRect box{1, 0, 3, 3};  // depths 2.125 .. 2.375, confidences 0.25 .. 1 per row
  const ConfidencePyramid::Verdict behind = pyramid.test(box, 2.5);
  EXPECT_TRUE(behind.failed);
  EXPECT_DOUBLE_EQ(behind.confidence, (0.25 + 0.5 + 0.75 + 1.0) / 4.0);
  EXPECT_FALSE(pyramid.test(box, 2.375).failed);  // texel x = 3 is as far as the box
  EXPECT_FALSE(pyramid.test(box, 2.0).failed);
  // Unknown depth (nothing sampled) is never nearer than a box.
  px[size_t(2) * w + 2].d_cull = std::numeric_limits<float>::infinity();
  pyramid.build(px, w, h);
  EXPECT_FALSE(pyramid.test(box, 2.5).failed);
}

// A ray with `per_bin` particles in each of 10 unit bins from depth 0.
struct UniformRay {
  std::vector<float> cum;
  explicit UniformRay(double per_bin) {
    for (int i = 0; i <= 10; ++i) cum.push_back(float(i * per_bin));
  }
  RayDensity ray() const { return {cum.data(), 10, 0.0, 1.0, 1.0}; }
};

TEST(DepthConfidence, AcceptanceFollowsEquations13To22) {
  const UniformRay u(100.0);
  const RayDensity ray = u.ray();
  // Nothing known yet: any nearer sample is taken.
  EXPECT_EQ(acceptance_probability(5.0, 0.1, INFINITY, 0.0, ray), 1.0);
  // A confident depth at 5 (OP = 500 * 0.9): a sample at 4.9 needs C_s > 0.9 * 500 / 510
  // (eq. 13), n = log(1 - C_s) / log(0.9) unique particles (eq. 15), k(d_s) samples from the 490
  // nearer (eq. 19), and p = 490 / 1000 (eq. 22).
  const double target = 500.0 / 510.0 * 0.9;
  const double n = std::log1p(-target) / std::log1p(-0.1);
  const double k = std::ceil(std::log1p(-n / 490.0) / std::log1p(-1.0 / 490.0));
  EXPECT_NEAR(acceptance_probability(4.9, 0.1, 5.0, 0.9, ray),
              binomial_tail(kSampleBudget, 0.49, int(k)), 1e-12);
  // A sample far nearer with almost nobody in front cannot reach the confidence: eq. 20 clamps.
  EXPECT_EQ(acceptance_probability(0.05, 0.01, 5.0, 0.9, ray), 0.0);
  // Eq. 8: with many particles in front each sample is new, so C = 1 - (1 - a)^k.
  double c = 0.0;
  for (uint32_t k2 = 1; k2 <= 5; ++k2) c = accumulate_confidence(c, 0.2, k2, 1e9);
  EXPECT_NEAR(c, 1.0 - std::pow(0.8, 5), 1e-6);
  // With one particle in front, repeated samples hit the same particle: no new coverage.
  double one = accumulate_confidence(0.0, 0.2, 1, 1.0);
  for (uint32_t k2 = 2; k2 <= 5; ++k2) one = accumulate_confidence(one, 0.2, k2, 1.0);
  EXPECT_NEAR(one, 0.2, 1e-12);
}

TEST(DepthConfidence, CullBufferTakesTheAccumulatedDepthOnlyWhenItOccludesMore) {
  const UniformRay u(100.0);
  const RayDensity ray = u.ray();
  ConfidencePixel px = ConfidencePixel::empty();
  update_pixel(&px, 5.0, 0.5, ray, 0.0, false);  // first sample: accepted, copied to cull
  EXPECT_EQ(px.d, 5.0f);
  EXPECT_EQ(px.d_cull, 5.0f);
  EXPECT_EQ(px.c_cull, 0.5f);
  for (int k = 0; k < 6; ++k) update_pixel(&px, 5.0, 0.5, ray, 0.0, false);
  EXPECT_GT(px.c_cull, 0.95f);
  // A nearer sample refused (u above any probability) accumulates into neither depth.
  const ConfidencePixel before = px;
  update_pixel(&px, 4.0, 0.5, ray, 1.0, false);
  EXPECT_EQ(px.d, before.d);
  EXPECT_EQ(px.d_cull, before.d_cull);
  // Accepted by a coin (u = 0.25 <= 1/2): the accumulation buffer restarts at 4 with C = alpha,
  // the cull buffer keeps 5 (OP(4, 0.5) = 300 < OP(5, c_cull) ~ 500).
  update_pixel(&px, 4.0, 0.5, ray, 0.25, true);
  EXPECT_EQ(px.d, 4.0f);
  EXPECT_EQ(px.c, 0.5f);
  EXPECT_EQ(px.d_cull, 5.0f);
}

// An fcc crystal of n^3 cells seen from outside, shuffled publication order.
struct Crystal {
  std::vector<double> xyz;
  std::vector<int32_t> type;
  explicit Crystal(int n) {
    const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
    std::vector<std::array<double, 3>> pts;
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
          for (const auto &b : basis)
            pts.push_back({(x + b[0]) * 1.5874, (y + b[1]) * 1.5874, (z + b[2]) * 1.5874});
    std::shuffle(pts.begin(), pts.end(), std::mt19937(7));
    for (const auto &p : pts) {
      xyz.insert(xyz.end(), p.begin(), p.end());
      type.push_back(int32_t(type.size() % 5));
    }
  }
  ParticleArrays arrays() const {
    ParticleDescription p{};
    p.count = int64_t(type.size());
    p.position = {xyz.data(), DataType::kFloat64, 0};
    p.type = {type.data(), DataType::kInt32, 0};
    ParticleArrays a;
    EXPECT_OK(ParticleArrays::validate(p, &a));
    return a;
  }
};

struct Rendered {
  Frame frame;
  CullStats stats;
  PageVector<uint64_t> drawn;
  std::vector<uint8_t> classes;  // per meshlet
  MeshletSet meshlets;
  std::vector<uint32_t> visible_bricks;
};

class Probabilistic : public ::testing::Test {
 protected:
  static SceneConfig scene(int size, OcclusionMode mode, double confidence = 0.95) {
    SceneConfig s;
    s.width = s.height = size;
    s.radius = 0.5;
    s.culling.occlusion = mode;
    s.culling.probabilistic.confidence = confidence;
    s.renderer = RendererChoice::kCpu;
    return s;
  }
  static Rendered render(const Crystal &c, const SceneConfig &s, int64_t step = 3) {
    const ParticleArrays p = c.arrays();
    glm::dvec3 lo(1e300), hi(-1e300);
    for (size_t i = 0; i < c.xyz.size(); i += 3) {
      const glm::dvec3 x(c.xyz[i], c.xyz[i + 1], c.xyz[i + 2]);
      lo = glm::min(lo, x), hi = glm::max(hi, x);
    }
    Camera cam;
    CameraConfig cc;
    cc.azimuth = 30, cc.elevation = 25;
    EXPECT_OK(make_camera(cc, lo, hi, s.radius, s.width, s.height, &cam));
    const BrickSet bricks = build_bricks(p, BrickOptions{});
    Rendered r;
    RankScene rank_scene(p, bricks, cam, s);
    rank_scene.step = step;
    RankDrawScratch scratch;
    RankDraw drawn;
    EXPECT_OK(draw_scene_on_rank(rank_scene, &scratch, &r.frame, &drawn));
    r.stats = drawn.cull;
    r.drawn = scratch.draw.spheres;
    const CpuSpherePass &pass = scratch.cpu_pass;
    const BrickSelection &sel = scratch.selection;
    if (s.culling.occlusion == OcclusionMode::kProbabilistic) {
      r.meshlets = pass.probabilistic().meshlets();
      for (uint32_t m = 0; m < r.meshlets.meshlets.size(); ++m)
        r.classes.push_back(uint8_t(pass.probabilistic().class_of(m)));
      r.meshlets = pass.probabilistic().meshlets();
      // Map each meshlet's slots to particle indices in place (brick offset = first of brick).
      for (size_t b = 0; b < bricks.bricks.size(); ++b)
        for (uint32_t m = r.meshlets.first_of_brick[b]; m < r.meshlets.first_of_brick[b + 1]; ++m)
          for (uint32_t j = 0; j < r.meshlets.meshlets[m].count; ++j) {
            uint32_t &slot = r.meshlets.slots[r.meshlets.meshlets[m].first + j];
            slot = bricks.order[bricks.bricks[b].first + slot];
          }
      for (const VisibleBrick &v : sel.visible) r.visible_bricks.push_back(v.brick);
    }
    return r;
  }
  static int64_t differing(const Frame &a, const Frame &b, int levels) {
    int64_t n = 0;
    for (size_t i = 0; i < a.pixel_count(); ++i)
      for (int ch = 0; ch < 3; ++ch)
        if (std::abs(int(a.rgba[4 * i + ch]) - int(b.rgba[4 * i + ch])) > levels) {
          ++n;
          break;
        }
    return n;
  }
};

TEST_F(Probabilistic, TwoRunsGiveTheSameBytesAndCullMuchOfACrystal) {
  const Crystal c(16);  // 16,384 atoms
  const SceneConfig s = scene(128, OcclusionMode::kProbabilistic);
  const Rendered a = render(c, s), b = render(c, s);
  EXPECT_EQ(a.frame.rgba, b.frame.rgba);
  EXPECT_EQ(a.frame.depth, b.frame.depth);
  EXPECT_EQ(a.classes, b.classes);
  EXPECT_EQ(a.stats.probabilistic.samples, b.stats.probabilistic.samples);
  // Much of a solid crystal is hidden (a small one: a fifth at least); the stats add up.
  const ProbabilisticStats &st = a.stats.probabilistic;
  EXPECT_GT(st.particles_culled, int64_t(c.type.size()) / 5);
  EXPECT_EQ(a.stats.occlusion_culled, st.particles_culled);
  EXPECT_EQ(a.stats.drawn + st.particles_culled, int64_t(c.type.size()));
  EXPECT_EQ(st.samples, st.iterations * kPassesPerIteration);
  EXPECT_GT(st.meshlets[int(OcclusionClass::kOccluded)], 0);
  EXPECT_GT(st.meshlets[int(OcclusionClass::kPotentiallyVisible)], 0);
  // Another step draws other random numbers (keyed by the step), a rerun of it the same again.
  const Rendered other = render(c, s, 4);
  EXPECT_EQ(other.frame.rgba, render(c, s, 4).frame.rgba);
}

// Every meshlet in class P is drawn in full; raising C_occ culls no more, and the image stays
// that of brute force: at 0.99 and above exactly (the limit), below within 0.1% of the pixels
// (the paper's anchor), while 0.9 culls a real share (so the comparison is not vacuous).
TEST_F(Probabilistic, NeverCullsClassPAndTendsToBruteForceAsConfidenceRises) {
  const Crystal c(20);  // 32,000 atoms of about 0.4 px radius: several per pixel
  const Rendered brute = render(c, scene(64, OcclusionMode::kNone));
  int64_t previous = int64_t(c.type.size());
  for (const double confidence : {0.9, 0.95, 0.99, 0.999}) {
    const Rendered r = render(c, scene(64, OcclusionMode::kProbabilistic, confidence));
    const std::set<uint64_t> drawn(r.drawn.begin(), r.drawn.end());
    int64_t p_meshlets = 0;
    for (const uint32_t b : r.visible_bricks)
      for (uint32_t m = r.meshlets.first_of_brick[b]; m < r.meshlets.first_of_brick[b + 1]; ++m) {
        if (r.classes[m] != uint8_t(OcclusionClass::kPotentiallyVisible)) continue;
        ++p_meshlets;
        const Meshlet &mesh = r.meshlets.meshlets[m];
        for (uint32_t j = 0; j < mesh.count; ++j) {
          const uint32_t i = r.meshlets.slots[mesh.first + j];
          EXPECT_TRUE(drawn.count(draw_entry(i, 1.0f))) << "particle " << i << " of class P";
        }
      }
    EXPECT_GT(p_meshlets, 0);
    const int64_t culled = r.stats.probabilistic.particles_culled;
    EXPECT_LE(culled, previous) << "C_occ " << confidence;
    previous = culled;
    if (confidence == 0.9) EXPECT_GT(culled, int64_t(c.type.size()) / 20);
    const int64_t diff = differing(brute.frame, r.frame, 0);
    if (confidence >= 0.99)
      EXPECT_EQ(diff, 0) << "C_occ " << confidence;
    else
      EXPECT_LE(diff, int64_t(brute.frame.pixel_count() / 1000)) << "C_occ " << confidence;
  }
}

// Ibrahim et al. 2022, §5.3 to the letter (quiet_share 0: no meshlet may change class) runs the
// default's iterations and then goes on while any class still moves: with random numbers keyed by
// (step, pixel, sample, iteration) it repeats the default run and continues, so it samples at
// least as long and culls at least as much, and on this crystal measurably more of both.
TEST_F(Probabilistic, StrictConvergenceGoesOnWhereTheDefaultToleranceStops) {
  const Crystal c(24);  // 55,296 atoms at 96^2: hundreds of meshlets creep from M to O
  SceneConfig s = scene(96, OcclusionMode::kProbabilistic);
  const Rendered loose = render(c, s);
  s.culling.probabilistic.quiet_share = 0.0;
  const Rendered strict = render(c, s);
  const ProbabilisticStats &a = loose.stats.probabilistic, &b = strict.stats.probabilistic;
  EXPECT_GT(b.iterations, a.iterations);
  EXPECT_GE(b.particles_culled, a.particles_culled);
  EXPECT_GT(b.meshlets[int(OcclusionClass::kOccluded)], a.meshlets[int(OcclusionClass::kOccluded)]);
  EXPECT_LE(b.iterations, kMaxIterations);
}

}  // namespace
}  // namespace lantern
