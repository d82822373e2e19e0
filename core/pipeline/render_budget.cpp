#include "core/pipeline/render_budget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace lantern {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The ladder's numbers, measured on the project's 2-core machine at 1024² on 2 ranks.
//
// Costs: each rung's whole frame through the pipeline relative to the rung above, the median of
// three scenes' ladder tables (fcc 1 M, void_impact, fcc 10 M; lantern-bench-budget, full quality
// = 4 samples + full-resolution screen AO;
// tests/bench/budget/results/ladder_fcc1m_void_impact_fcc10m_1024_first.txt). PSNR: the knob's
// image against its configured setting, from the benches that measured each knob alone:
//
//   step               cost (3 scenes)         PSNR      source of the PSNR
//   AO full -> half    0.69 (0.69 0.66 0.78)   39.2 dB   lantern-bench-cues --kernels 3: half
//                                                        against full 39.2 / 41.1 dB (fcc 1 M,
//                                                        void_impact)
//   samples 64 -> 16   0.40 (16 -> 4's)        43.8 dB   lantern-bench --samples 1,4,16: 16
//                                                        against 64 samples (cost not measured)
//   samples 16 -> 4    0.43 (fcc 1 M, 2 ranks) 35.1 dB   same, 4 against 64 (3.91x -> 1.68x)
//   AO half -> off     0.89 (0.89 0.88 1.07)   32.5 dB   lantern-bench-cues --kernels 3: plain
//                                                        against full AO 32.8 / 32.5 dB
//   samples 4 -> 1     0.44 (0.44 0.38 0.60)   25.0 dB   lantern-bench --samples: 1 against 64
//   object AO nodes    0.96 (fcc 1 M)          39.0 dB   lantern-bench-cues --object-nodes
//   -> half                                              131072,262144: half the nodes against
//                                                        2^18 39.0 / 40.9 dB (fcc 1 M, void_impact;
//                                                        the 1 M-atom LJ melt in situ 36.8); cost:
//                                                        the stage 3.1 -> 2.1 ms of a 25 ms frame
//                                                        (void_impact's volume is not capped: 1.0)
//   object AO off      0.89 (0.90 0.92)        23.4 dB   lantern-bench-cues: plain against object
//                                                        AO 26.8 / 23.4 dB (fcc 1 M, void_impact)
//   lod 1 -> 0.5       0.82 (0.82 0.88 0.82)   16.6 dB   lantern-bench --opaque-lod, CPU raster
//                                                        + hzb: fcc 10 M 16.6, void_impact 19.0
//   lod 0.5 -> 0.25    0.96 (0.96 1.01 0.90)   15.7 dB   same: 15.7 / 18.2 dB
//   lod 0.25 -> 0.1    0.85 (0.85 0.96 0.81)   15.0 dB   same: 15.0 / 17.4 dB
//   lod 0.1 -> 0.05    0.85 (0.87 0.84)        14.3 dB   lantern-bench-budget's ladder, fcc 1 M
//   lod 0.05 -> 0.02   0.90 (0.87 0.93)        13.6 dB   and fcc 10 M (ladder_lod002_fcc10m_
//                                                        fcc1m_1024.txt): 0.5-0.9 and 0.7 dB
//                                                        below the rung above
//
// (The ladder tables' own PSNR against full quality agree within 2.5 dB for AO and samples; for
// level of detail they are 1.5-5 dB better than the estimate: fcc's pixels are many small spheres.)
//
// Ordered by squared error added per millisecond saved (each step taken only where the scene's
// configuration has something to give up): half-resolution AO adds 1.2e-4 for 31-58 ms; 16 -> 4
// samples 3.1e-4 for about 75 ms of a 16-sample fcc 1 M frame (64 -> 16 less still); AO off
// 5.6e-4 for 10-14 ms; 4 -> 1 samples about 3e-3 for 43-88 ms (on void_impact, per millisecond,
// slightly cheaper than AO off; on fcc 1 M dearer; AO off is kept first as the smaller error);
// level of detail, whose uniform prefix loses the pixels (15-19 dB, SSIM 0.5-0.7), 2e-2 for 0-18 %
// a step, comes last. Object AO on half the nodes adds 1.3e-4 for about 1 ms, as 4 -> 1 samples
// add per millisecond, so it comes after them: its cost was measured on one-sample frames (on a
// 4-sample fcc 1 M frame it saves 1 % and is judged not paying); object AO off adds 4.6e-3 for
// about 11 % of the frame, after both and before level of detail.
constexpr double kAoHalfCost = 0.69, kAoHalfPsnr = 39.2;
constexpr double kAoOffCost = 0.89, kAoOffPsnr = 32.5;
constexpr double kObjectAoHalfNodesCost = 0.96, kObjectAoHalfNodesPsnr = 39.0;
constexpr double kObjectAoOffCost = 0.89, kObjectAoOffPsnr = 23.4;
struct SampleStep {
  int from, to;
  double cost, psnr_db;
};
constexpr SampleStep kManySampleSteps[] = {{64, 16, 0.40, 43.8}, {16, 4, 0.43, 35.1}};
constexpr SampleStep kLastSampleStep = {4, 1, 0.44, 25.0};
struct LodStep {
  double fraction, cost, psnr_db;
};
// 0.05 and 0.02: on fcc 10 M lod 0.1 still draws 65 k particles and each further step saves 7-16 %
// of the frame; where they do not pay (void_impact) the controller skips them once measured.
constexpr LodStep kLodSteps[] = {{0.5, 0.82, 16.6},
                                 {0.25, 0.96, 15.7},
                                 {0.1, 0.85, 15.0},
                                 {0.05, 0.85, 14.3},
                                 {0.02, 0.90, 13.6}};

double mse_of(double psnr_db) {
  return std::isinf(psnr_db) ? 0.0 : std::pow(10.0, -psnr_db / 10.0);
}

// The knobs' errors against their configured settings, added as squared errors.
double rung_psnr(double ao_psnr, double samples_psnr, double lod_psnr) {
  const double mse = mse_of(ao_psnr) + mse_of(samples_psnr) + mse_of(lod_psnr);
  return mse == 0.0 ? kInf : -10.0 * std::log10(mse);
}

bool screen_ao(const SceneConfig &scene) {
  return scene.ambient_occlusion.enabled &&
         scene.ambient_occlusion.method == AmbientOcclusionMethod::kScreen;
}

bool object_ao(const SceneConfig &scene) {
  return scene.ambient_occlusion.enabled &&
         scene.ambient_occlusion.method == AmbientOcclusionMethod::kObject;
}

// The configured max_nodes halved, within the key's range.
int64_t half_nodes(const SceneConfig &scene) {
  return std::max<int64_t>(64, scene.ambient_occlusion.max_nodes / 2);
}

double clamp_ms(double ms) {
  return std::min(ms, BudgetController::kMaxMs);
}

}  // namespace

std::vector<BudgetRung> budget_ladder(const SceneConfig &scene) {
  std::vector<BudgetRung> ladder(1);
  BudgetRung r;
  r.samples = scene.samples;
  r.lod_fraction = scene.lod.fraction;
  ladder[0] = r;
  double ao_psnr = kInf, samples_psnr = kInf, lod_psnr = kInf;
  const auto push = [&](std::string what, double cost) {
    r.gives_up = std::move(what);
    r.step_cost = cost;
    r.psnr_db = rung_psnr(ao_psnr, samples_psnr, lod_psnr);
    ladder.push_back(r);
  };
  if (screen_ao(scene) && scene.ambient_occlusion.resolution == AoResolution::kFull) {
    r.ao = BudgetAo::kHalf;
    ao_psnr = kAoHalfPsnr;
    push("ao half", kAoHalfCost);
  }
  const auto fewer_samples = [&](const SampleStep &s) {
    if (r.samples != s.from) return;
    r.samples = s.to;
    samples_psnr = s.psnr_db;  // against 64 samples: close to the configured ones' error
    push("samples " + std::to_string(s.to), s.cost);
  };
  for (const SampleStep &s : kManySampleSteps) fewer_samples(s);
  if (screen_ao(scene)) {
    r.ao = BudgetAo::kOff;
    ao_psnr = kAoOffPsnr;
    push("ao off", kAoOffCost);
  }
  fewer_samples(kLastSampleStep);
  if (object_ao(scene) && half_nodes(scene) < scene.ambient_occlusion.max_nodes) {
    r.ao = BudgetAo::kHalf;
    ao_psnr = kObjectAoHalfNodesPsnr;
    push("ao half nodes", kObjectAoHalfNodesCost);
  }
  if (object_ao(scene)) {
    r.ao = BudgetAo::kOff;
    ao_psnr = kObjectAoOffPsnr;
    push("ao off", kObjectAoOffCost);
  }
  for (const LodStep &l : kLodSteps)
    if (l.fraction < r.lod_fraction) {
      r.lod_fraction = l.fraction;
      lod_psnr = l.psnr_db;
      char what[32];
      std::snprintf(what, sizeof what, "lod %g", l.fraction);
      push(what, l.cost);
    }
  return ladder;
}

SceneConfig scene_at_rung(const SceneConfig &scene, const BudgetRung &rung) {
  SceneConfig s = scene;
  s.samples = rung.samples;
  s.lod.fraction = rung.lod_fraction;
  if (screen_ao(scene) && rung.ao == BudgetAo::kHalf)
    s.ambient_occlusion.resolution = AoResolution::kHalf;
  if (screen_ao(scene) && rung.ao == BudgetAo::kOff) s.ambient_occlusion.enabled = false;
  if (object_ao(scene) && rung.ao == BudgetAo::kHalf)
    s.ambient_occlusion.max_nodes = half_nodes(scene);
  if (object_ao(scene) && rung.ao == BudgetAo::kOff) s.ambient_occlusion.enabled = false;
  return s;
}

std::string budget_ao_name(const SceneConfig &scene, const BudgetRung &rung) {
  if (object_ao(scene)) {
    if (rung.ao == BudgetAo::kOff) return "off";
    return rung.ao == BudgetAo::kHalf ? "object_half_nodes" : "object";
  }
  if (!screen_ao(scene)) return "none";
  if (rung.ao == BudgetAo::kOff) return "off";
  if (rung.ao == BudgetAo::kHalf) return "half";
  return scene.ambient_occlusion.resolution == AoResolution::kFull ? "full" : "half";
}

BudgetController::BudgetController(std::vector<double> step_costs)
    : step_(std::move(step_costs)),
      ratio_(step_.size(), 1.0),
      learned_(step_.size(), false),
      error_(step_.size(), kNaN) {
  if (step_.empty()) {  // a ladder has at least rung 0
    step_.assign(1, 1.0);
    ratio_.assign(1, 1.0);
    learned_.assign(1, false);
    error_.assign(1, kNaN);
  }
  for (double &c : step_)
    if (!(c > 0.0) || !std::isfinite(c)) c = 1.0;  // a prior that is not a cost says nothing
  learned_[0] = true;                              // rung 0 is the unit
  fill_unlearned_ratios();
}

// A rung not measured yet costs what the nearest measured rung above it costs, times the priors
// of the steps between; where a measured rung below bounds the run too, every prior step of it is
// scaled alike (geometrically) so that the run ends at that rung's measured cost.
void BudgetController::fill_unlearned_ratios() {
  const size_t n = ratio_.size();
  for (size_t above = 0; above + 1 < n;) {
    size_t below = above + 1;
    while (below < n && !learned_[below]) ++below;
    double scale = 1.0;
    if (below < n && below > above + 1) {
      double prior = 1.0;
      for (size_t i = above + 1; i <= below; ++i) prior *= step_[i];
      scale = std::pow(ratio_[below] / (ratio_[above] * prior), 1.0 / double(below - above));
    }
    for (size_t i = above + 1; i < std::min(below, n); ++i)
      ratio_[i] = std::clamp(ratio_[i - 1] * step_[i] * scale, 1e-9, 1e9);
    above = below;
  }
}

// Rung 0 pays; a measured rung pays when at least kMinSaving cheaper than the cheapest better
// measured rung that pays. A rung not measured yet pays (its prediction is the priors', scaled
// by noisy neighbours: it is judged once measured, which happens only where it is predicted to
// fit or to be the cheapest).
std::vector<bool> BudgetController::paying() const {
  std::vector<bool> pay(ratio_.size(), true);
  double cheapest = ratio_[0];
  for (size_t i = 1; i < ratio_.size(); ++i) {
    if (!learned_[i]) continue;
    pay[i] = ratio_[i] < (1.0 - kMinSaving) * cheapest;
    if (pay[i]) cheapest = ratio_[i];
  }
  return pay;
}

double BudgetController::predicted_ms(int rung) const {
  if (!measured() || rung < 0 || rung >= rungs()) return kNaN;
  return clamp_ms(level_ms_ * ratio_[size_t(rung)]);
}

double BudgetController::predicted_error(int rung) const {
  if (!measured() || rung < 0 || rung >= rungs()) return kNaN;
  const size_t k = size_t(rung);
  const double own = !learned_[k] ? kPriorError : std::isnan(error_[k]) ? 0.0 : error_[k];
  return std::max(noise_, own);
}

void BudgetController::record(int rung, double ms) {
  if (rung < 0 || rung >= rungs() || std::isnan(ms) || !(ms > 0.0)) return;
  ms = clamp_ms(ms);
  const size_t k = size_t(rung);
  if (measured() && learned_[k]) {
    // A learned rung measured again: how far off its prediction was (means of the last few).
    const double off = std::min(std::abs(ms / predicted_ms(rung) - 1.0), 1.0);
    error_[k] = std::isnan(error_[k]) ? off : 0.5 * (error_[k] + off);
    noise_ = 0.5 * (noise_ + off);
  }
  if (measured() && last_rung_ != rung) {
    // Two rungs measured on consecutive steps of a steady run: their ratio is learned, and the
    // level (rung 0's cost) stays where the previous step put it. A rung learned before keeps
    // the geometric mean of its estimates, so one noisy pair does not decide it alone.
    const double pair = std::clamp(ratio_[size_t(last_rung_)] * ms / last_ms_, 1e-9, 1e9);
    ratio_[k] = learned_[k] && k != 0 ? std::sqrt(ratio_[k] * pair) : pair;
    if (k == 0) {  // rung 0 is the unit: the level moves instead
      level_ms_ = ms;
      ratio_[0] = 1.0;
    }
    learned_[k] = true;
    fill_unlearned_ratios();
  } else {
    // The same rung again (or the first measurement): the run's level moved.
    level_ms_ = ms / ratio_[k];
  }
  last_rung_ = rung;
  last_ms_ = ms;
}

// Nothing fits: the paying rung predicted cheapest, unless a paying rung not measured yet may be
// cheaper than the cheapest measured one (its prediction less kExploreShare): the cheapest such is
// tried. Each rung is tried at most once this way (it is measured then), so this settles.
int BudgetController::cheapest_to_try(const std::vector<bool> &pay) const {
  int cheapest = 0;
  double measured_ms = kInf;
  for (int j = 0; j < rungs(); ++j)
    if (pay[size_t(j)] && learned_[size_t(j)] && predicted_ms(j) < measured_ms) {
      measured_ms = predicted_ms(j);
      cheapest = j;
    }
  int best = cheapest;
  double best_ms = kInf;
  for (int j = 0; j < rungs(); ++j) {
    if (!pay[size_t(j)] || learned_[size_t(j)]) continue;
    const double ms = predicted_ms(j);
    if (ms * (1.0 - kExploreShare) < measured_ms && ms < best_ms) {
      best = j;
      best_ms = ms;
    }
  }
  return best;
}

int BudgetController::choose(double budget_ms) {
  unmet_ = false;
  if (!measured() || std::isnan(budget_ms) || !(budget_ms > 0.0)) {
    rung_ = 0;
    return rung_;
  }
  const std::vector<bool> pay = paying();
  int up = 0;  // the nearest paying rung better than the current one
  for (int j = 0; j < rung_ && j < rungs(); ++j)
    if (pay[size_t(j)]) up = j;
  for (int j = 0; j < rungs(); ++j) {
    if (!pay[size_t(j)]) continue;
    // A better rung than the current one only with a margin: the run's noise, or the priors'
    // error for a rung not measured yet. (Not the rung's own error: one noisy measurement of
    // it would keep it out for good, one rung lower than needed.)
    const double margin = std::max({kMinMargin, noise_, learned_[size_t(j)] ? 0.0 : kPriorError});
    const double allowed = j < rung_ ? budget_ms / (1.0 + margin) : budget_ms;
    if (predicted_ms(j) <= allowed) {
      // Up one paying rung at a time: each step up is measured before the next (a noisy cheap
      // step does not jump straight back to full quality); down as far as needed at once.
      rung_ = j < rung_ ? std::max(j, up) : j;
      return rung_;
    }
  }
  rung_ = cheapest_to_try(pay);
  unmet_ = true;
  return rung_;
}

nlohmann::json BudgetStats::to_json() const {
  const auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; };
  return {{"ms", number(budget_ms)},
          {"rung", rung},
          {"rungs", rungs},
          {"gives_up", gives_up},
          {"lod_fraction", lod_fraction},
          {"samples", samples},
          {"ambient_occlusion", ambient_occlusion},
          {"predicted_ms", number(predicted_ms)},
          {"predicted_error", number(predicted_error)},
          {"measured_ms", measured_ms},
          // null for rung 0: the configured picture itself
          {"psnr_db", number(psnr_db)},
          {"unmet", unmet},
          {"skipped", skipped},
          {"note", note.empty() ? nlohmann::json(nullptr) : nlohmann::json(note)}};
}

SceneConfig SceneBudget::choose(const SceneConfig &scene, double budget_ms, BudgetStats *out) {
  std::vector<BudgetRung> next = budget_ladder(scene);
  if (next != ladder) {  // a new scene, or a live change of its settings: measure afresh
    std::vector<double> costs;
    for (const BudgetRung &r : next) costs.push_back(r.step_cost);
    controller = BudgetController(std::move(costs));
    ladder = std::move(next);
  }
  const int k = controller.choose(budget_ms);
  const BudgetRung &r = ladder[size_t(k)];
  out->budget_ms = budget_ms;
  out->rung = k;
  out->rungs = int(ladder.size());
  out->gives_up = r.gives_up;
  out->lod_fraction = r.lod_fraction;
  out->samples = r.samples;
  out->ambient_occlusion = budget_ao_name(scene, r);
  out->predicted_ms = controller.predicted_ms(k);
  out->predicted_error = controller.predicted_error(k);
  for (int j = 1; j < controller.rungs(); ++j)
    if (!controller.pays(j)) out->skipped.push_back(ladder[size_t(j)].gives_up);
  out->psnr_db = r.psnr_db;
  out->unmet = controller.unmet();
  return scene_at_rung(scene, r);
}

}  // namespace lantern
