#include "core/bricks/index_runs.h"

#include "core/common/page_allocator.h"

namespace lantern {

namespace {

// Where the run that starts at i ends: as long as the particles belong to its brick or to one
// other (the first other one met), or to no brick for a run of none.
int64_t run_end(const uint32_t *owner, int64_t n, int64_t i, uint32_t *other) {
  const uint32_t brick = owner[i];
  int64_t e = i + 1;
  *other = kNoBrick;
  if (brick == kNoBrick) {
    while (e < n && owner[e] == kNoBrick) ++e;
    return e;
  }
  for (; e < n; ++e) {
    const uint32_t o = owner[e];
    if (o == brick) continue;
    if (o == kNoBrick || (*other != kNoBrick && o != *other)) break;
    *other = o;
  }
  return e;
}

}  // namespace

PageVector<IndexRun> runs_of_owners(const uint32_t *owner, int64_t n, int64_t held,
                                    PageVector<uint64_t> *in_other) {
  // Counted first, then listed into a vector of the exact size: growing it run by run copied it
  // about twice over (and faulted in each new block) at 100 M particles.
  const size_t most = size_t(held / kMinMeanRun) + 1;
  size_t count = 0, held_runs = 0;
  for (int64_t i = 0; i < n;) {
    uint32_t other;
    const int64_t e = run_end(owner, n, i, &other);
    if (owner[i] != kNoBrick && ++held_runs > most) {  // too short to pay
      in_other->clear();
      return {};
    }
    ++count;
    i = e;
  }
  PageVector<IndexRun> runs;
  runs.reserve(count + 1);
  in_other->assign(size_t((n + 63) / 64), 0);
  for (int64_t i = 0; i < n;) {
    IndexRun run;
    run.first = uint32_t(i);
    run.brick = owner[i];
    const int64_t e = run_end(owner, n, i, &run.other);
    if (run.other != kNoBrick)
      for (int64_t k = i + 1; k < e; ++k)
        if (owner[k] == run.other) (*in_other)[size_t(k >> 6)] |= uint64_t(1) << (k & 63);
    runs.push_back(run);
    i = e;
  }
  runs.push_back({uint32_t(n), kNoBrick, kNoBrick});
  return runs;
}

void list_runs(int64_t bound, BrickSet *set) {
  PageVector<uint32_t> owner(static_cast<size_t>(bound), kNoBrick);
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
