// lantern-bench's probabilistic-culling modes (Ibrahim et al. 2022): `probabilistic` at three
// confidence thresholds and the paper's random-acceptance baseline (Table 4's "random"), all drawn
// by the CPU raster, and the note printed with them (iterations, samples, meshlet classes, pixels
// beyond 2 levels of the exact CPU image).
#pragma once

#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/culling/cull_stats.h"
#include "core/view/frame.h"

namespace lantern::bench {

struct ProbabilisticMode {
  // probabilistic@0.99, @0.95, @0.90, random50, and probabilistic@0.95+strict, random50+strict
  // (convergence when no meshlet changed class at all, Ibrahim et al. 2022, §5.3 to the letter)
  std::string name;
  ProbabilisticConfig config;
};

std::vector<ProbabilisticMode> probabilistic_modes();

// " (iterations I, samples S, meshlets P/L/M/O a/b/c/d, O meshlets x%, >2 levels vs exact: N
// px)"; the last part only when `exact` is given. "O meshlets" is the culled share of Ibrahim et
// al.'s Table 4: meshlets, not particles, and of the frustum's bricks only.
std::string probabilistic_note(const ProbabilisticStats &st, const Frame &image,
                               const Frame *exact);

}  // namespace lantern::bench
