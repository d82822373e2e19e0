#include "core/bricks/index_runs.h"

namespace lantern {

std::vector<IndexRun> runs_of_owners(const uint32_t *owner, int64_t n, int64_t held,
                                     std::vector<uint64_t> *in_other) {
  std::vector<IndexRun> runs;
  in_other->assign(size_t((n + 63) / 64), 0);
  const size_t most = size_t(held / kMinMeanRun) + 1;
  size_t held_runs = 0;
  for (int64_t i = 0; i < n;) {
    IndexRun run;
    run.first = uint32_t(i);
    run.brick = owner[i];
    int64_t e = i + 1;
    if (run.brick == kNoBrick) {
      while (e < n && owner[e] == kNoBrick) ++e;
    } else {
      // Grow while the particles belong to the run's brick or to one other.
      for (; e < n; ++e) {
        const uint32_t o = owner[e];
        if (o == run.brick) continue;
        if (o == kNoBrick || (run.other != kNoBrick && o != run.other)) break;
        run.other = o;
        (*in_other)[size_t(e >> 6)] |= uint64_t(1) << (e & 63);
      }
      if (++held_runs > most) {  // too short to pay
        in_other->clear();
        return {};
      }
    }
    runs.push_back(run);
    i = e;
  }
  runs.push_back({uint32_t(n), kNoBrick, kNoBrick});
  runs.shrink_to_fit();
  return runs;
}

void list_runs(int64_t bound, BrickSet *set) {
  std::vector<uint32_t> owner(static_cast<size_t>(bound), kNoBrick);
  for (size_t b = 0; b < set->bricks.size(); ++b) {
    const Brick &br = set->bricks[b];
    for (uint32_t k = 0; k < br.count; ++k) {
      const uint32_t i = set->order[br.first + k];
      if (int64_t(i) < bound) owner[i] = uint32_t(b);
    }
  }
  set->runs = runs_of_owners(owner.data(), bound, set->particle_count(), &set->in_other);
}

}  // namespace lantern
