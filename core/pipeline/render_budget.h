// A scene's time budget (budget_ms, budget_percent): which settings to draw it with on the next
// rendered step, decided from the measured costs of the previous steps.
//
// The ladder is a list of settings from the scene as configured (rung 0) down to the cheapest;
// each rung gives up one more thing, in the order of image error added per millisecond saved that
// the benchmarks measured (render_budget.cpp quotes them). The controller predicts every rung's
// cost from the measured ones and picks the first rung (the best picture) predicted to fit, among
// the rungs that pay (measured cheaper than every better one): down as far as needed at once, up
// one rung a step and only with a margin of the prediction's measured error (hysteresis).
//
// Plain values and a deterministic controller: fed the same (reduced) costs, every rank picks the
// same rung, so the ranks draw with the same settings. Not thread-safe; one per scene.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/config/config.h"

namespace lantern {

// How a rung draws the scene's ambient occlusion: as configured, cheaper (screen: at half
// resolution; object: on half the nodes, `max_nodes` / 2), or not at all.
enum class BudgetAo { kAsConfigured, kHalf, kOff };

// One setting of the ladder, and what it gives up against rung 0.
struct BudgetRung {
  double lod_fraction = 1.0;  // lod.fraction drawn
  int samples = 1;            // rays per pixel drawn
  BudgetAo ao = BudgetAo::kAsConfigured;
  std::string gives_up;  // against the rung above: "ao half", "samples 4", "ao off", "lod 0.5", ...
  // Benchmarked cost of this rung relative to the rung above (1 for rung 0): the controller's
  // prior until the rung has been measured in this run.
  double step_cost = 1.0;
  // Estimated PSNR (dB) of this rung's image against rung 0's (+inf for rung 0): each knob's
  // benchmarked error against its configured setting, the knobs' squared errors added.
  double psnr_db = std::numeric_limits<double>::infinity();

  bool operator==(const BudgetRung &o) const {
    return lod_fraction == o.lod_fraction && samples == o.samples && ao == o.ao;
  }
  bool operator!=(const BudgetRung &o) const { return !(*this == o); }
};

// The scene's ladder: rung 0 draws it exactly as configured.
std::vector<BudgetRung> budget_ladder(const SceneConfig &scene);

// The scene as `rung` draws it (rung 0: the scene unchanged).
SceneConfig scene_at_rung(const SceneConfig &scene, const BudgetRung &rung);

// The ambient occlusion the rung draws for this scene: screen "full" | "half", object "object" |
// "object_half_nodes", either "off"; "none" where the scene has none.
std::string budget_ao_name(const SceneConfig &scene, const BudgetRung &rung);

// Picks rungs from measured costs. Costs are milliseconds of a whole scene (the slowest rank's).
// Timings that are not numbers, zero or negative are ignored; larger than kMaxMs counts as kMaxMs.
//
// The model: rung j costs level x ratio[j] (ratio[0] = 1). A rung's ratio is learned when it is
// measured on the step after another rung (the level taken as steady between two steps); a rung
// not measured yet is predicted from the measured rungs around it, the benchmarks' step costs
// scaled to agree with them. Every measurement of a learned rung is also compared with what was
// predicted for it: those relative errors give each rung's error estimate and the run's noise.
//
// A measured rung pays only while it is at least kMinSaving cheaper than every better measured rung
// that pays: a rung measured not cheaper than a better one is not chosen again (until the ladder is
// rebuilt), so a budget nothing meets is drawn at the cheapest rung measured, not the last one.
class BudgetController {
 public:
  static constexpr double kMaxMs = 1e9;
  // A measured rung pays only when it saves at least this share of every better rung's cost.
  static constexpr double kMinSaving = 0.05;
  // Step up to a better rung only when its prediction plus the run's noise (at least this share;
  // kPriorError for a rung not measured yet) fits the budget: hysteresis, so that noise of a few
  // percent does not flip two rungs.
  static constexpr double kMinMargin = 0.05;
  // The run's noise (relative error of a prediction) assumed until a rung is measured twice.
  static constexpr double kInitialNoise = 0.10;
  // The relative error of a rung predicted from the benchmarks' step costs (not measured yet):
  // its margin for a step up.
  static constexpr double kPriorError = 0.15;
  // When no rung fits, a rung not measured yet is tried if it may be this share cheaper than
  // predicted and so cheaper than the cheapest measured rung (the benchmarks' step costs differ
  // between scenes and loads by up to about this much).
  static constexpr double kExploreShare = 0.30;

  BudgetController() = default;
  // step_costs[i]: the prior cost of rung i relative to rung i-1 (step_costs[0] is ignored).
  explicit BudgetController(std::vector<double> step_costs);

  // The rung to draw next within budget_ms. Before any measurement, or without a usable budget
  // (not a positive number), rung 0: the first rendered step draws full quality and measures it.
  // Otherwise the best paying rung predicted to fit: down as far as needed at once, up one paying
  // rung a step and only with the margin. When none fits, the cheapest paying rung (unmet() is
  // then true); a rung not measured yet that may be cheaper still (its prediction less
  // kExploreShare below the cheapest measured one) is tried first, once.
  int choose(double budget_ms);
  // Records that `rung` cost `ms`.
  void record(int rung, double ms);

  int rung() const { return rung_; }
  int rungs() const { return int(ratio_.size()); }
  bool measured() const { return last_rung_ >= 0; }
  bool unmet() const { return unmet_; }
  // Predicted cost of `rung` (ms), NaN before the first measurement.
  double predicted_ms(int rung) const;
  // The relative error estimate of predicted_ms(rung): the run's noise, or more where the rung's
  // own predictions were further off, or kPriorError where it was never measured.
  double predicted_error(int rung) const;
  // Whether the rung's cost was measured in this run.
  bool learned(int rung) const { return rung >= 0 && rung < rungs() && learned_[size_t(rung)]; }
  // Whether the rung pays: not measured yet, or measured at least kMinSaving cheaper than every
  // better measured rung that pays.
  bool pays(int rung) const { return rung >= 0 && rung < rungs() && paying()[size_t(rung)]; }

 private:
  void fill_unlearned_ratios();
  std::vector<bool> paying() const;
  int cheapest_to_try(const std::vector<bool> &pay) const;

  std::vector<double> step_;   // priors: cost relative to the rung above
  std::vector<double> ratio_;  // cost relative to rung 0
  std::vector<bool> learned_;  // ratio_[i] measured in this run (else from the priors)
  std::vector<double> error_;  // per rung: mean relative error of its predictions (NaN: none yet)
  double noise_ = kInitialNoise;  // the same over all rungs
  double level_ms_ = 0.0;         // predicted cost of rung 0 now
  int last_rung_ = -1;            // rung of the last measurement, -1 before the first
  double last_ms_ = 0.0;          // its cost
  int rung_ = 0;                  // the rung chosen last
  bool unmet_ = false;
};

// What a scene's budget chose and measured on one step: JSON "budget" of its stats line.
struct BudgetStats {
  double budget_ms =
      0.0;  // this step's budget (NaN: not known yet, the first steps of budget_percent)
  int rung = 0, rungs = 1;
  std::string gives_up;  // the rung's own step down ("" for rung 0)
  double lod_fraction = 1.0;
  int samples = 1;
  std::string ambient_occlusion;  // full | half | off | none
  double predicted_ms = 0.0;      // the controller's prediction for this rung (NaN: none yet)
  double predicted_error = 0.0;   // its relative error estimate (NaN: none yet)
  double measured_ms = 0.0;       // the slowest rank's cost of the scene this step
  double psnr_db = 0.0;           // the rung's estimated error against full quality (inf: exact)
  bool unmet = false;             // even the cheapest rung is predicted over budget
  // Rungs skipped as not paying: each one's gives_up.
  std::vector<std::string> skipped;
  // Said once per scene, on the first step the budget cannot be met ("" otherwise).
  std::string note;
  nlohmann::json to_json() const;
};

// A scene's budget kept between steps: its ladder and controller (reset when the ladder changes,
// e.g. after a live configuration change).
struct SceneBudget {
  std::vector<BudgetRung> ladder;
  BudgetController controller;
  bool warned_unmet = false;  // said once that the budget cannot be met

  // The scene to draw this step within budget_ms (NaN: none known yet) and what was chosen.
  SceneConfig choose(const SceneConfig &scene, double budget_ms, BudgetStats *out);
};

}  // namespace lantern
