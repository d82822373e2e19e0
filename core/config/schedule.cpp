#include <algorithm>

#include "core/config/config.h"

namespace lantern {

bool Schedule::due(int64_t step) const {
  if (every <= 0 && steps.empty()) return true;  // no schedule keys: every step renders
  if (every > 0 && step >= start && (step - start) % every == 0) return true;
  // The loader sorts `steps`, but a hand-built Schedule may not be sorted: search linearly.
  return std::find(steps.begin(), steps.end(), step) != steps.end();
}

}  // namespace lantern
