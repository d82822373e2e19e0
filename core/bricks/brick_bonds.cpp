#include "core/bricks/brick_bonds.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include <glm/geometric.hpp>

#include "core/common/ms_since.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

constexpr uint32_t kNoBrick = std::numeric_limits<uint32_t>::max();
// How many halves ahead the refit asks for the memory it will read (refit_brick_bonds).
constexpr size_t kAhead = 16;

bool same_box(const PeriodicBox &a, const PeriodicBox &b) {
  return a.length == b.length && a.periodic == b.periodic;
}

}  // namespace

void build_brick_bonds(const ParticleArrays &particles, const BondArrays &bonds,
                       const BrickSet &bricks, const PeriodicBox *box, BrickBonds *out,
                       BrickBondsScratch *scratch) {
  BrickBondsScratch local;
  BrickBondsScratch &w = scratch ? *scratch : local;
  BrickBonds &r = *out;
  r.bonds = bonds.count();
  r.skipped = 0, r.ungrouped = 0;
  r.first_error = Status();
  const size_t brick_count = bricks.bricks.size();
  const int64_t owned = particles.count(), reach = bonds.reach(particles);
  const bool both_halves = bonds.listing() == BondListing::kListedOnce;
  // slot_of[i]: where owned particle i sits in bricks.order (brick after brick), kNoBrick for one
  // the bricks left out; brick_of[i]: its brick.
  w.slot_of.assign(size_t(2 * owned), kNoBrick);
  uint32_t *const slot_of = w.slot_of.data(), *const brick_of = slot_of + owned;
  for (uint32_t b = 0; b < brick_count; ++b) {
    const Brick &brick = bricks.bricks[b];
    for (uint32_t k = 0; k < brick.count; ++k) {
      const uint32_t i = bricks.order[brick.first + k];
      slot_of[i] = brick.first + k, brick_of[i] = b;
    }
  }
  // The halves this rank draws, each with its key: twice the slot of the atom it is filed under,
  // plus one for a ghost's half, so that a counting sort by key puts them brick after brick, an
  // owned atom's own halves together and the ghosts' halves filed with it after them. The bounds
  // of each brick's halves (both ends of every half) and each atom's reach are gathered on the way.
  const glm::dvec3 inf(std::numeric_limits<double>::infinity());
  r.lo.assign(brick_count, inf);
  r.hi.assign(brick_count, -inf);
  r.reach.assign(size_t(reach), 0.0);
  w.unsorted.resize(size_t(2 * bonds.count()));
  w.key.resize(size_t(2 * bonds.count()));
  const size_t keys = 2 * bricks.order.size();
  w.next.assign(keys + 1, 0);
  size_t n = 0;
  visit_positions(particles, [&](const auto &pos) {
    for (int64_t k = 0; k < bonds.count(); ++k) {
      glm::dvec3 x0, x1;
      if (!bonds.drawable(k, owned, pos, &x0, &x1)) {  // check_bond words the error
        if (Status s = bonds.check_bond(k, particles); r.first_error.ok()) r.first_error = s;
        ++r.skipped;
        continue;
      }
      const uint32_t a = uint32_t(bonds.first(k)), b = uint32_t(bonds.second(k));
      if (!particles.kept(a) || !particles.kept(b)) {
        ++r.ungrouped;
        continue;
      }
      const glm::dvec3 ends[2] = {half_bond_end(x0, x1, box), half_bond_end(x1, x0, box)};
      const uint32_t atoms[2] = {a, b};
      const glm::dvec3 *centres[2] = {&x0, &x1};
      for (int e = 0; e < 2; ++e) {
        const uint32_t atom = atoms[e], partner = atoms[1 - e];
        const bool mine = int64_t(atom) < owned;
        if (!mine && !both_halves) continue;  // the ghost's owner draws it
        const uint32_t filed = mine ? atom : partner;
        if (slot_of[filed] == kNoBrick) continue;  // not in a brick: cannot happen when checked
        const glm::dvec3 &x = *centres[e], &end = ends[e];
        const uint32_t brick = brick_of[filed];
        r.lo[brick] = glm::min(r.lo[brick], glm::min(x, end));
        r.hi[brick] = glm::max(r.hi[brick], glm::max(x, end));
        r.reach[atom] = std::max(r.reach[atom], glm::length(end - x));
        w.unsorted[n] = {atom, partner, uint32_t(k)};
        w.key[n] = 2 * slot_of[filed] + (mine ? 0 : 1);
        ++w.next[w.key[n] + 1];
        ++n;
      }
    }
  });
  // Counting sort by key (stable: in list order within a key); bricks.order holds the bricks
  // one after another, so brick b's halves start at the offset of its first slot.
  for (size_t key = 0; key < keys; ++key) w.next[key + 1] += w.next[key];
  r.first.resize(brick_count + 1);
  for (size_t b = 0; b < brick_count; ++b) r.first[b] = w.next[2 * size_t(bricks.bricks[b].first)];
  r.first[brick_count] = uint32_t(n);
  r.halves.resize(n);
  for (size_t h = 0; h < n; ++h) r.halves[w.next[w.key[h]]++] = w.unsorted[h];
}

bool refit_brick_bonds(const ParticleArrays &particles, const BondArrays &bonds,
                       const BrickSet &bricks, const PeriodicBox *box, BrickBonds *out) {
  BrickBonds &r = *out;
  const size_t brick_count = bricks.bricks.size();
  if (r.first.size() != brick_count + 1) return false;
  const glm::dvec3 inf(std::numeric_limits<double>::infinity());
  r.lo.assign(brick_count, inf);
  r.hi.assign(brick_count, -inf);
  r.reach.assign(size_t(bonds.reach(particles)), 0.0);
  bool ok = true;
  // Brick after brick, as the halves are filed: min and max of non-zero finite values do not
  // depend on the order they are met in, so the bounds are the build's (which meets them in list
  // order), and so is every reach (a maximum of lengths). A brick's halves come in runs of one
  // atom (an owned atom's own halves are consecutive): each run reads its atom once, adds it to
  // the bounds once, and writes its reach once, the square root of its longest squared length -
  // sqrt is correctly rounded, so monotonic, and that root is the longest of the halves' lengths.
  visit_positions(particles, [&](const auto &pos) {
    const HalfBond *const halves = r.halves.data();
    double *const reach = r.reach.data();
    const size_t count = r.halves.size();
    // A copy the compiler may keep in registers: the stores to reach could alias *box.
    const PeriodicBox local_box = box ? *box : PeriodicBox();
    const PeriodicBox *const image = box ? &local_box : nullptr;
    // The atoms, partners and reach entries are scattered over the host's order: ask for them
    // kAhead halves before they are read, or nearly every half waits on a cache miss. Written
    // out where it is used: GCC deletes a call to a helper that only prefetches (it deems it
    // free of effects) unless the helper was inlined first.
    for (size_t k = 0; k < std::min(kAhead, count); ++k) {
      pos.prefetch(halves[k].atom), pos.prefetch(halves[k].partner);
      __builtin_prefetch(reach + halves[k].atom, 0, 3);
    }
    for (size_t b = 0; b < brick_count && ok; ++b) {
      glm::dvec3 lo = inf, hi = -inf;
      const uint32_t last = r.first[b + 1];
      for (uint32_t k = r.first[b]; k < last;) {
        const uint32_t atom = halves[k].atom;
        const glm::dvec3 x = pos.get(atom);
        if (!finite_position(x)) return void(ok = false);
        lo = glm::min(lo, x), hi = glm::max(hi, x);
        double longest = 0.0;  // squared
        for (; k < last && halves[k].atom == atom; ++k) {
          if (k + kAhead < count) {
            const HalfBond &ahead = halves[k + kAhead];
            pos.prefetch(ahead.atom), pos.prefetch(ahead.partner);
            __builtin_prefetch(reach + ahead.atom, 0, 3);
          }
          const glm::dvec3 partner = pos.get(halves[k].partner);
          if (!finite_position(partner)) return void(ok = false);
          const glm::dvec3 end = half_bond_end(x, partner, image);
          lo = glm::min(lo, end), hi = glm::max(hi, end);
          const glm::dvec3 along = end - x;
          longest = std::max(longest, glm::dot(along, along));
        }
        reach[atom] = std::max(reach[atom], std::sqrt(longest));
      }
      if (r.first[b] != last)
        for (int c = 0; c < 3; ++c) ok &= lo[c] != 0.0 && hi[c] != 0.0;
      r.lo[b] = lo, r.hi[b] = hi;
    }
  });
  return ok;
}

bool BondCache::same_indices(const BondArrays &bonds) {
  const auto n = size_t(bonds.count());
  bool same = indices_valid_ && indices_.size() == 2 * n, valid = true;
  indices_.resize(2 * n);
  for (size_t k = 0; k < n; ++k) {
    const int64_t a = bonds.first(int64_t(k)), b = bonds.second(int64_t(k));
    constexpr int64_t kMax = std::numeric_limits<uint32_t>::max();
    valid &= a >= 0 && a <= kMax && b >= 0 && b <= kMax;
    same &= indices_[2 * k] == uint32_t(a) && indices_[2 * k + 1] == uint32_t(b);
    indices_[2 * k] = uint32_t(a), indices_[2 * k + 1] = uint32_t(b);
  }
  indices_valid_ = valid;
  return same && valid;
}

bool BondCache::can_refit(const ParticleArrays &particles, const BondArrays &bonds,
                          const BrickSet &bricks, const PeriodicBox *box, bool indices_same) const {
  // A build depends on the indices, the owned and ghost counts, the listing, the group, the
  // bricks' slots and the box; on the positions only through the bounds, the reach and the
  // finiteness check, all of which the refit redoes. A build that left a bond out is not kept:
  // its halves would not cover every bond's ends.
  const bool box_same = (box != nullptr) == had_box_ && (!box || same_box(*box, box_));
  return used_ && indices_same && box_same && bricks.order_generation != 0 &&
         bricks.order_generation == order_generation_ && owned_ == particles.count() &&
         ghosts_ == bonds.ghost_count() && listing_ == bonds.listing() && !particles.has_mask() &&
         built_.bonds == bonds.count() && built_.skipped == 0 && built_.ungrouped == 0;
}

const BrickBonds &BondCache::for_step(const ParticleArrays &particles, const BondArrays &bonds,
                                      uint64_t serial, const BrickSet &bricks,
                                      const PeriodicBox *box, int64_t step, double *build_ms) {
  const bool box_same = (box != nullptr) == had_box_ && (!box || same_box(*box, box_));
  if (used_ && generation_ == bricks.generation && bricks.generation != 0 && serial_ == serial &&
      box_same && step_ == step)
    return built_;
  const auto t0 = std::chrono::steady_clock::now();
  const bool indices_same = same_indices(bonds);
  reused_ = can_refit(particles, bonds, bricks, box, indices_same) &&
            refit_brick_bonds(particles, bonds, bricks, box, &built_);
  if (reused_)
    ++reuses_;
  else
    build_brick_bonds(particles, bonds, bricks, box, &built_, &scratch_);
  generation_ = bricks.generation;
  order_generation_ = bricks.order_generation;
  serial_ = serial;
  owned_ = particles.count();
  ghosts_ = bonds.ghost_count();
  listing_ = bonds.listing();
  had_box_ = box != nullptr;
  if (box) box_ = *box;
  step_ = step;
  used_ = true;
  *build_ms += ms_since(t0);
  return built_;
}

}  // namespace lantern
