#include "core/bricks/index_runs.h"

#include <algorithm>
#include <optional>
#include <vector>

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

// The brick numbers of owners that are the bricks' first slots. The bricks' first slots increase
// with their numbers; a table of the first brick at or after every 1024th slot leaves a few entries
// to step over (a binary search over the bricks with a cache of recent answers cost a tenth of the
// build at 100 M particles, where a gas's runs visit its bricks in random order).
class BrickNumbers {
 public:
  BrickNumbers(const std::vector<Brick> &bricks, int64_t slots) : first_(bricks.size() + 1) {
    for (size_t b = 0; b < bricks.size(); ++b) first_[b] = bricks[b].first;
    first_[bricks.size()] = ~0u;  // a sentinel past every slot
    at_.resize(size_t(slots >> kShift) + 1);
    uint32_t b = 0;
    for (size_t k = 0; k < at_.size(); ++k) {
      while (first_[b] < (uint64_t(k) << kShift)) ++b;
      at_[k] = b;
    }
  }
  uint32_t operator()(uint32_t owner) const {
    if (owner == kNoBrick) return kNoBrick;
    uint32_t n = at_[owner >> kShift];
    while (first_[n] < owner) ++n;
    return n;
  }

 private:
  static constexpr int kShift = 10;
  std::vector<uint32_t> first_, at_;
};

}  // namespace

IndexRuns runs_of_owners(const uint32_t *owner, int64_t n, int64_t held,
                         PageVector<uint64_t> *in_other, const std::vector<Brick> *numbered_by) {
  // Counted first, then listed into a vector of the exact size: growing it run by run copied it
  // about twice over (and faulted in each new block) at 100 M particles.
  const size_t most = size_t(held / kMinMeanRun) + 1;
  const auto block_end = [n](int64_t i) {
    return std::min<int64_t>(n, (i / IndexRuns::kBlock + 1) * int64_t(IndexRuns::kBlock));
  };
  const auto storable = [](uint32_t b) { return b == kNoBrick || b <= IndexRuns::kLargestBrick; };
  if (numbered_by && numbered_by->size() > size_t(IndexRuns::kLargestBrick) + 1) {
    in_other->clear();
    return {};
  }
  size_t count = 0, held_runs = 0;
  for (int64_t i = 0; i < n;) {
    uint32_t other;
    const int64_t e = run_end(owner, block_end(i), i, &other);
    if ((owner[i] != kNoBrick && ++held_runs > most) ||  // too short to pay
        (!numbered_by && (!storable(owner[i]) || !storable(other)))) {
      in_other->clear();
      return {};
    }
    ++count;
    i = e;
  }
  std::optional<BrickNumbers> numbers;
  if (numbered_by) numbers.emplace(*numbered_by, held);
  const auto number = [&](uint32_t o) { return numbers ? (*numbers)(o) : o; };
  IndexRuns runs;
  runs.reserve(count + 1);
  in_other->assign(size_t((n + 63) / 64), 0);
  for (int64_t i = 0; i < n;) {
    IndexRun run;
    run.first = uint32_t(i);
    const int64_t e = run_end(owner, block_end(i), i, &run.other);
    if (run.other != kNoBrick)
      for (int64_t k = i + 1; k < e; ++k)
        if (owner[k] == run.other) (*in_other)[size_t(k >> 6)] |= uint64_t(1) << (k & 63);
    run.brick = number(owner[i]);
    run.other = number(run.other);
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
