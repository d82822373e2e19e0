// The time budget's controller as a pure function of injected costs (no clock): full quality when
// it fits, monotone steps down, back up when the cost falls, hysteresis, never past the cheapest
// rung, timings that are not usable; and the ladder built from a scene, and the keys' errors.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/config/config_loader.h"
#include "core/pipeline/render_budget.h"
#include "tests/support/config_error_expect.h"

namespace lantern::testing {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Priors of a five-rung ladder: each rung half the one above.
BudgetController halving(int rungs = 5) {
  return BudgetController(std::vector<double>(size_t(rungs), 0.5));
}

// A simulated scene: rung j truly costs level * truth[j]; `steps` steps of choose, then record.
// Returns the rungs chosen.
std::vector<int> run(BudgetController &c, double budget, const std::vector<double> &truth,
                     const std::vector<double> &levels) {
  std::vector<int> chosen;
  for (double level : levels) {
    const int k = c.choose(budget);
    chosen.push_back(k);
    c.record(k, level * truth[size_t(k)]);
  }
  return chosen;
}

const std::vector<double> kTruth = {1.0, 0.5, 0.25, 0.125, 0.0625};

TEST(BudgetController, FirstStepIsFullQualityAndStaysThereWhenItFits) {
  BudgetController c = halving();
  EXPECT_EQ(c.choose(1.0), 0);  // nothing measured: full quality, to measure it
  EXPECT_FALSE(c.measured());
  const std::vector<int> chosen = run(c, 40.0, kTruth, std::vector<double>(6, 39.0));
  for (int k : chosen) EXPECT_EQ(k, 0);
  EXPECT_FALSE(c.unmet());
}

TEST(BudgetController, StepsDownMonotonicallyAsTheCostRises) {
  BudgetController c = halving();
  std::vector<double> levels;
  for (double l = 10.0; l < 2000.0; l *= 1.3) levels.push_back(l);
  const std::vector<int> chosen = run(c, 40.0, kTruth, levels);
  for (size_t i = 1; i < chosen.size(); ++i) EXPECT_GE(chosen[i], chosen[i - 1]) << i;
  EXPECT_EQ(chosen.front(), 0);
  EXPECT_EQ(chosen.back(), 4);
}

TEST(BudgetController, StepsBackUpWhenTheCostFalls) {
  BudgetController c = halving();
  run(c, 40.0, kTruth, std::vector<double>(4, 150.0));  // 150 ms full: rung 2 (37.5 ms)
  EXPECT_EQ(c.rung(), 2);
  std::vector<double> falling;
  for (double l = 150.0; l > 10.0; l *= 0.8) falling.push_back(l);
  const std::vector<int> chosen = run(c, 40.0, kTruth, falling);
  for (size_t i = 1; i < chosen.size(); ++i) EXPECT_LE(chosen[i], chosen[i - 1]) << i;
  EXPECT_EQ(c.choose(40.0), 0);
}

TEST(BudgetController, HysteresisKeepsItFromOscillating) {
  // Full quality always costs 42 ms, just over a 40 ms budget; the next rung 21 or 19 ms on
  // alternate steps (noise), so that from it full quality looks like 38 ms now and then. Once
  // stepped down it stays down: 38 ms is over the step-up share of the budget.
  BudgetController c = halving();
  std::vector<int> chosen;
  for (int i = 0; i < 20; ++i) {
    const int k = c.choose(40.0);
    chosen.push_back(k);
    c.record(k, k == 0 ? 42.0 : (i % 2 ? 21.0 : 19.0) * std::pow(0.5, k - 1));
  }
  int changes = 0;
  for (size_t i = 1; i < chosen.size(); ++i) changes += chosen[i] != chosen[i - 1];
  EXPECT_EQ(changes, 1);
  EXPECT_EQ(chosen.back(), 1);
  // Well under the step-up share, it goes back up.
  run(c, 40.0, kTruth, std::vector<double>(3, 30.0));
  EXPECT_EQ(c.rung(), 0);
}

TEST(BudgetController, NeverPastTheCheapestRung) {
  BudgetController c = halving();
  const std::vector<int> chosen = run(c, 1.0, kTruth, std::vector<double>(5, 1e6));
  EXPECT_EQ(chosen.back(), 4);
  EXPECT_TRUE(c.unmet());
  EXPECT_EQ(c.choose(1e-300), 4);
}

TEST(BudgetController, LearnsRatiosThePriorsGotWrongAndSettles) {
  // The priors say each rung halves the cost; truly the first two steps save little. After
  // three steps no step is more than 20 % over the budget.
  BudgetController c = halving();
  const std::vector<double> truth = {1.0, 0.9, 0.8, 0.3, 0.1};
  const std::vector<double> level(12, 100.0);
  std::vector<int> chosen = run(c, 40.0, truth, level);
  for (size_t i = 3; i < chosen.size(); ++i)
    EXPECT_LE(100.0 * truth[size_t(chosen[i])], 1.2 * 40.0) << "step " << i;
  EXPECT_EQ(chosen.back(), 3);
}

TEST(BudgetController, UnusableTimingsAreIgnoredOrBounded) {
  BudgetController c = halving();
  for (double bad : {kNaN, 0.0, -5.0, -kInf}) {
    c.record(0, bad);
    EXPECT_FALSE(c.measured()) << bad;
    EXPECT_EQ(c.choose(40.0), 0);
  }
  c.record(-1, 10.0);  // not a rung
  c.record(9, 10.0);
  EXPECT_FALSE(c.measured());
  c.record(0, kInf);  // bounded: predicts kMaxMs, the cheapest rung, unmet
  EXPECT_TRUE(c.measured());
  EXPECT_LE(c.predicted_ms(0), BudgetController::kMaxMs);
  EXPECT_EQ(c.choose(40.0), 4);
  EXPECT_TRUE(c.unmet());
  c.record(4, 1e300);  // huge, then a usable timing again: back to the best rung that fits
  c.record(4, 1.0);
  EXPECT_TRUE(std::isfinite(c.predicted_ms(0)));
  EXPECT_LT(c.choose(40.0), 4);
  // A budget that is not a positive number is no budget: full quality.
  for (double bad : {kNaN, 0.0, -1.0}) EXPECT_EQ(c.choose(bad), 0) << bad;
  // Priors that are not costs are taken as "no saving".
  BudgetController odd(std::vector<double>{1.0, kNaN, -2.0, 0.0});
  odd.record(0, 10.0);
  for (int r = 0; r < odd.rungs(); ++r) EXPECT_EQ(odd.predicted_ms(r), 10.0) << r;
  BudgetController empty{std::vector<double>{}};
  EXPECT_EQ(empty.rungs(), 1);
  EXPECT_EQ(empty.choose(1.0), 0);
}

TEST(BudgetController, StepsBackUpToTheRungThatFitsAfterTheCostReturns) {
  // Rung 1 costs 90 % of the budget. The scene gets dearer for three steps (the controller steps
  // down), then returns to its cost: the controller goes back to rung 1 once the noise it measured
  // settles, not staying a rung lower than needed.
  BudgetController c = halving();
  std::vector<double> levels(3, 72.0);
  levels.insert(levels.end(), 3, 90.0);
  levels.insert(levels.end(), 8, 72.0);
  const std::vector<int> chosen = run(c, 40.0, kTruth, levels);
  EXPECT_EQ(chosen[1], 1);
  EXPECT_EQ(chosen[5], 2);  // 45 ms at rung 1: down
  EXPECT_EQ(chosen.back(), 1);
  EXPECT_EQ(c.choose(40.0), 1);
  EXPECT_FALSE(c.unmet());
}

// The ladder of a scene with 4 samples and full-resolution screen AO, its benchmarked step costs
// as the priors.
std::vector<double> ladder_priors() {
  SceneConfig scene;
  scene.samples = 4;
  scene.ambient_occlusion.enabled = true;
  scene.ambient_occlusion.resolution = AoResolution::kFull;
  std::vector<double> priors;
  for (const BudgetRung &r : budget_ladder(scene)) priors.push_back(r.step_cost);
  return priors;
}

TEST(BudgetController, SkipsRungsMeasuredNotCheaperAndStepsBackUp) {
  // The costs void_impact measured on a loaded machine (lantern-bench-budget): one sample without
  // AO (rung 3) takes 53 ms, the level-of-detail rungs below it 59-65 ms (the last two as lod 0.1).
  // Under 40 ms nothing fits: the controller tries the rungs that may be cheapest, once each, and
  // settles on rung 3, never drawing a rung again once it was measured not cheaper than a better
  // one.
  const std::vector<double> priors = ladder_priors();
  ASSERT_EQ(priors.size(), 9u);
  BudgetController c(priors);
  const std::vector<double> truth = {245.7, 173.9, 156.0, 53.1, 63.0, 59.3, 65.2, 64.0, 63.5};
  std::vector<int> chosen;
  std::vector<bool> drawn(truth.size(), false);
  for (int i = 0; i < 14; ++i) {
    const int k = c.choose(40.0);
    if (k > 3) EXPECT_FALSE(drawn[size_t(k)]) << "step " << i << ": rung " << k << " again";
    drawn[size_t(k)] = true;
    chosen.push_back(k);
    c.record(k, truth[size_t(k)]);
  }
  for (size_t i = 8; i < chosen.size(); ++i) EXPECT_EQ(chosen[i], 3) << "step " << i;
  EXPECT_TRUE(c.unmet());
  EXPECT_TRUE(c.pays(3));
  for (int r = 4; r < 9; ++r) EXPECT_FALSE(c.pays(r)) << r;
  EXPECT_NEAR(c.predicted_ms(3), 53.1, 1e-9);
  EXPECT_LT(c.predicted_error(3), 0.1);  // measured again and again: the noise is small

  // The scene gets cheaper (every rung at 0.19 of those costs: rung 1 33 ms, rung 0 47 ms): back
  // up, one paying rung a step, to the best rung that fits.
  chosen.clear();
  for (int i = 0; i < 6; ++i) {
    const int k = c.choose(40.0);
    chosen.push_back(k);
    c.record(k, 0.19 * truth[size_t(k)]);
  }
  for (size_t i = 1; i < chosen.size(); ++i) EXPECT_LE(chosen[i], chosen[i - 1]) << i;
  EXPECT_EQ(chosen.back(), 1);
  EXPECT_FALSE(c.unmet());
}

TEST(BudgetController, ARungThatPaysIsKeptAndTheLastIsTheCheapest) {
  // Every rung truly cheaper than the one above: none is skipped, and a budget nothing meets
  // draws the last rung, as the ladder promises.
  const std::vector<double> priors = ladder_priors();
  BudgetController c(priors);
  const std::vector<double> truth = {173.5, 120.1, 106.6, 47.3, 38.8, 34.3, 29.2, 25.0, 22.5};
  const std::vector<int> chosen = run(c, 10.0, truth, std::vector<double>(8, 1.0));
  EXPECT_EQ(chosen.back(), 8);
  EXPECT_TRUE(c.unmet());
  for (int r = 0; r < 9; ++r)
    if (c.learned(r)) EXPECT_TRUE(c.pays(r)) << r;
}

TEST(BudgetLadder, GivesUpInTheMeasuredOrderAndRungZeroIsTheScene) {
  SceneConfig scene;
  scene.samples = 4;
  scene.ambient_occlusion.enabled = true;
  scene.ambient_occlusion.resolution = AoResolution::kFull;
  const std::vector<BudgetRung> ladder = budget_ladder(scene);
  std::vector<std::string> steps;
  for (size_t i = 1; i < ladder.size(); ++i) steps.push_back(ladder[i].gives_up);
  EXPECT_EQ(steps, (std::vector<std::string>{"ao half", "ao off", "samples 1", "lod 0.5",
                                             "lod 0.25", "lod 0.1", "lod 0.05", "lod 0.02"}));
  // From 64 samples, 16 and 4 come before AO off (far less error per millisecond saved).
  scene.samples = 64;
  std::vector<std::string> many;
  for (const BudgetRung &r : budget_ladder(scene)) many.push_back(r.gives_up);
  EXPECT_EQ(many, (std::vector<std::string>{"", "ao half", "samples 16", "samples 4", "ao off",
                                            "samples 1", "lod 0.5", "lod 0.25", "lod 0.1",
                                            "lod 0.05", "lod 0.02"}));
  scene.samples = 4;
  EXPECT_TRUE(std::isinf(ladder[0].psnr_db));
  for (size_t i = 1; i < ladder.size(); ++i) {
    EXPECT_LT(ladder[i].psnr_db, ladder[i - 1].psnr_db) << i;  // each step adds error
    EXPECT_GT(ladder[i].step_cost, 0.0);
    EXPECT_LT(ladder[i].step_cost, 1.0);  // ... and saves time
  }
  const SceneConfig top = scene_at_rung(scene, ladder[0]);
  EXPECT_EQ(top.samples, 4);
  EXPECT_EQ(top.lod.fraction, 1.0);
  EXPECT_TRUE(top.ambient_occlusion.enabled);
  EXPECT_EQ(top.ambient_occlusion.resolution, AoResolution::kFull);
  EXPECT_EQ(budget_ao_name(scene, ladder[0]), "full");
  const SceneConfig bottom = scene_at_rung(scene, ladder.back());
  EXPECT_EQ(bottom.samples, 1);
  EXPECT_EQ(bottom.lod.fraction, 0.02);
  EXPECT_FALSE(bottom.ambient_occlusion.enabled);
  EXPECT_EQ(budget_ao_name(scene, ladder.back()), "off");

  // A plain scene has only the level of detail to give up; one already at lod 0.3 less of it.
  SceneConfig plain;
  plain.lod.fraction = 0.3;
  const std::vector<BudgetRung> short_ladder = budget_ladder(plain);
  ASSERT_EQ(short_ladder.size(), 5u);
  EXPECT_EQ(short_ladder[1].gives_up, "lod 0.25");
  EXPECT_EQ(budget_ao_name(plain, short_ladder[4]), "none");
  EXPECT_FALSE(scene_at_rung(plain, short_ladder[4]).ambient_occlusion.enabled);
}

// Object-space occlusion: half the nodes after one sample instead of four (as much error per
// millisecond saved, measured on one-sample frames), then off, before the level of detail.
TEST(BudgetLadder, ObjectOcclusionGivesUpHalfItsNodesThenItself) {
  SceneConfig scene;
  scene.samples = 4;
  scene.lod.fraction = 0.3;
  scene.ambient_occlusion.enabled = true;
  scene.ambient_occlusion.method = AmbientOcclusionMethod::kObject;
  scene.ambient_occlusion.max_nodes = 100000;
  const std::vector<BudgetRung> ladder = budget_ladder(scene);
  std::vector<std::string> steps;
  for (const BudgetRung &r : ladder) steps.push_back(r.gives_up);
  EXPECT_EQ(steps, (std::vector<std::string>{"", "samples 1", "ao half nodes", "ao off", "lod 0.25",
                                             "lod 0.1", "lod 0.05", "lod 0.02"}));
  for (size_t i = 1; i < ladder.size(); ++i) {
    EXPECT_LT(ladder[i].psnr_db, ladder[i - 1].psnr_db) << i;
    EXPECT_LT(ladder[i].step_cost, 1.0) << i;
  }
  const std::string names[] = {"object", "object", "object_half_nodes", "off"};
  const int64_t nodes[] = {100000, 100000, 50000, 100000};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(budget_ao_name(scene, ladder[i]), names[i]) << i;
    const SceneConfig s = scene_at_rung(scene, ladder[i]);
    EXPECT_EQ(s.ambient_occlusion.enabled, i < 3) << i;
    EXPECT_EQ(s.ambient_occlusion.max_nodes, nodes[i]) << i;
    EXPECT_EQ(s.ambient_occlusion.method, AmbientOcclusionMethod::kObject) << i;
  }
  EXPECT_EQ(scene_at_rung(scene, ladder[1]).samples, 1);
  // At the smallest max_nodes there is no half to give up.
  scene.ambient_occlusion.max_nodes = 64;
  EXPECT_EQ(budget_ladder(scene)[2].gives_up, "ao off");
}

TEST(BudgetKeys, AreReadAndBadValuesNameTheKey) {
  Config c;
  ASSERT_TRUE(load_config("budget_percent: 1\nscenes: [{name: a, budget_ms: 40}]\n", &c).ok());
  EXPECT_EQ(c.budget_percent, 1.0);
  EXPECT_EQ(c.scenes[0].budget_ms, 40.0);
  ASSERT_TRUE(load_config("scenes: [{name: a}]\n", &c).ok());
  EXPECT_FALSE(c.budget_percent);
  EXPECT_FALSE(c.scenes[0].budget_ms);
  for (const char *bad : {"-1", "0", ".nan", ".inf", "fast", "[1]"})
    expect_config_error(std::string("scenes: [{name: a, budget_ms: ") + bad + "}]\n",
                        {"budget_ms"});
  for (const char *bad : {"-1", "0", "100.5", "101", ".nan", "all"})
    expect_config_error(std::string("budget_percent: ") + bad + "\nscenes: [{name: a}]\n",
                        {"budget_percent"});
  EXPECT_TRUE(load_config("budget_percent: 100\nscenes: [{name: a}]\n", &c).ok());
}

}  // namespace
}  // namespace lantern::testing
