#include "core/bricks/brick_bonds.h"

#include <chrono>
#include <limits>
#include <utility>

#include "core/common/ms_since.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

constexpr uint32_t kNoBrick = std::numeric_limits<uint32_t>::max();

// brick_of[i]: the brick holding owned particle i, kNoBrick for one the bricks left out.
std::vector<uint32_t> brick_of_particles(const BrickSet &bricks, int64_t count) {
  std::vector<uint32_t> brick_of(size_t(count), kNoBrick);
  for (uint32_t b = 0; b < bricks.bricks.size(); ++b) {
    const Brick &brick = bricks.bricks[b];
    for (uint32_t k = 0; k < brick.count; ++k) brick_of[bricks.order[brick.first + k]] = b;
  }
  return brick_of;
}

bool same_box(const PeriodicBox &a, const PeriodicBox &b) {
  return a.length == b.length && a.periodic == b.periodic;
}

}  // namespace

void build_brick_bonds(const ParticleArrays &particles, const BondArrays &bonds,
                       const BrickSet &bricks, const PeriodicBox *box, BrickBonds *out) {
  BrickBonds &r = *out;
  r = BrickBonds();
  r.bonds = bonds.count();
  const size_t brick_count = bricks.bricks.size();
  const int64_t owned = particles.count();
  const bool both_halves = bonds.listing() == BondListing::kListedOnce;
  const std::vector<uint32_t> brick_of = brick_of_particles(bricks, owned);
  // The halves this rank draws, each with its brick; then a counting sort by brick.
  std::vector<HalfBond> unsorted;
  std::vector<uint32_t> unsorted_brick;
  unsorted.reserve(size_t(2 * bonds.count()));
  unsorted_brick.reserve(size_t(2 * bonds.count()));
  for (int64_t k = 0; k < bonds.count(); ++k) {
    if (Status s = bonds.check_bond(k, particles); !s.ok()) {
      if (r.first_error.ok()) r.first_error = std::move(s);
      ++r.skipped;
      continue;
    }
    const uint32_t a = uint32_t(bonds.first(k)), b = uint32_t(bonds.second(k));
    if (!particles.kept(a) || !particles.kept(b)) {
      ++r.ungrouped;
      continue;
    }
    for (const auto &[atom, partner] : {std::pair{a, b}, std::pair{b, a}}) {
      const bool mine = int64_t(atom) < owned;
      if (!mine && !both_halves) continue;  // the ghost's owner draws it
      const uint32_t brick = brick_of[mine ? atom : partner];
      if (brick == kNoBrick) continue;  // not in a brick: cannot happen for a checked bond
      unsorted.push_back({atom, partner, uint32_t(k)});
      unsorted_brick.push_back(brick);
    }
  }
  r.first.assign(brick_count + 1, 0);
  for (const uint32_t b : unsorted_brick) ++r.first[b + 1];
  for (size_t b = 0; b < brick_count; ++b) r.first[b + 1] += r.first[b];
  r.halves.resize(unsorted.size());
  {
    std::vector<uint32_t> next(r.first.begin(), r.first.end() - 1);
    for (size_t h = 0; h < unsorted.size(); ++h) r.halves[next[unsorted_brick[h]]++] = unsorted[h];
  }
  // Bounds of each brick's halves: both ends of every half.
  const glm::dvec3 inf(std::numeric_limits<double>::infinity());
  r.lo.assign(brick_count, inf);
  r.hi.assign(brick_count, -inf);
  visit_positions(particles, [&](const auto &pos) {
    for (size_t b = 0; b < brick_count; ++b) {
      glm::dvec3 lo = inf, hi = -inf;
      for (uint32_t h = r.first[b]; h < r.first[b + 1]; ++h) {
        const glm::dvec3 x = pos.get(r.halves[h].atom);
        const glm::dvec3 end = half_bond_end(x, pos.get(r.halves[h].partner), box);
        lo = glm::min(lo, glm::min(x, end));
        hi = glm::max(hi, glm::max(x, end));
      }
      r.lo[b] = lo, r.hi[b] = hi;
    }
  });
}

const BrickBonds &BondCache::for_step(const ParticleArrays &particles, const BondArrays &bonds,
                                      uint64_t serial, const BrickSet &bricks,
                                      const PeriodicBox *box, int64_t step, double *build_ms) {
  const bool box_same = (box != nullptr) == had_box_ && (!box || same_box(*box, box_));
  if (used_ && generation_ == bricks.generation && bricks.generation != 0 && serial_ == serial &&
      box_same && step_ == step)
    return built_;
  const auto t0 = std::chrono::steady_clock::now();
  build_brick_bonds(particles, bonds, bricks, box, &built_);
  generation_ = bricks.generation;
  serial_ = serial;
  had_box_ = box != nullptr;
  if (box) box_ = *box;
  step_ = step;
  used_ = true;
  *build_ms += ms_since(t0);
  return built_;
}

}  // namespace lantern
