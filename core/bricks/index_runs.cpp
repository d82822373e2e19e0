#include "core/bricks/index_runs.h"

namespace lantern {

std::vector<IndexRun> runs_of_owners(const uint32_t *owner, int64_t n, int64_t held) {
  std::vector<IndexRun> runs;
  const size_t most = size_t(held / kMinMeanRun) + 1;
  size_t held_runs = 0;
  for (int64_t i = 0; i < n;) {
    const uint32_t b = owner[i];
    int64_t e = i + 1;
    while (e < n && owner[e] == b) ++e;
    if (b != kNoBrick && ++held_runs > most) return {};  // too short to pay
    runs.push_back({uint32_t(i), b});
    i = e;
  }
  runs.push_back({uint32_t(n), kNoBrick});
  runs.shrink_to_fit();
  return runs;
}

std::vector<IndexRun> runs_of(const BrickSet &set, int64_t bound) {
  std::vector<uint32_t> owner(static_cast<size_t>(bound), kNoBrick);
  for (size_t b = 0; b < set.bricks.size(); ++b) {
    const Brick &br = set.bricks[b];
    for (uint32_t k = 0; k < br.count; ++k) {
      const uint32_t i = set.order[br.first + k];
      if (int64_t(i) < bound) owner[i] = uint32_t(b);
    }
  }
  return runs_of_owners(owner.data(), bound, set.particle_count());
}

}  // namespace lantern
