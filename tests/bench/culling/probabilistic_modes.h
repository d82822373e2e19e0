// lantern-bench's seed 004 modes: `probabilistic` at three confidence thresholds and the paper's
// random-acceptance baseline (Table 4's "random"), all drawn by the CPU raster, and the note
// printed with them (iterations, samples, meshlet classes, pixels beyond 2 levels of the exact
// CPU image).
#pragma once

#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/culling/cull_stats.h"
#include "core/view/frame.h"

namespace lantern::bench {

struct ProbabilisticMode {
  std::string name;  // probabilistic@0.99, probabilistic@0.95, probabilistic@0.90, random50
  ProbabilisticConfig config;
};

std::vector<ProbabilisticMode> probabilistic_modes();

// " (iterations I, samples S, meshlets P/L/M/O a/b/c/d, >2 levels vs exact: N px)"; the last
// part only when `exact` is given.
std::string probabilistic_note(const ProbabilisticStats &st, const Frame &image,
                               const Frame *exact);

}  // namespace lantern::bench
