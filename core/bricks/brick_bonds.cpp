#include "core/bricks/brick_bonds.h"

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <glm/geometric.hpp>

#include "core/common/double_pair.h"
#include "core/common/ms_since.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

constexpr uint32_t kNoBrick = std::numeric_limits<uint32_t>::max();
// How many halves ahead the refit asks for the memory it will read (refit_brick_bonds).
constexpr size_t kAhead = 16;

// std::sqrt of a square (never negative): the same correctly rounded root, without the call to
// the library's sqrt that GCC keeps for a negative argument (errno), which would make the refit's
// loop save and restore its sums around it.
inline double root_of_square(double v) {
#if defined(__SSE2__)
  return _mm_cvtsd_f64(_mm_sqrt_sd(_mm_setzero_pd(), _mm_set_sd(v)));
#else
  return std::sqrt(v);
#endif
}

bool same_box(const PeriodicBox &a, const PeriodicBox &b) {
  return a.length == b.length && a.periodic == b.periodic && a.tilt == b.tilt;
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
    const auto owned = uint32_t(particles.count());
    // The atoms, partners and reach entries are scattered over the host's order: ask for them
    // kAhead halves before they are read, or nearly every half waits on a cache miss. Written
    // out where it is used: GCC deletes a call to a helper that only prefetches (it deems it
    // free of effects) unless the helper was inlined first.
    for (size_t k = 0; k < std::min(kAhead, count); ++k) {
      pos.prefetch(halves[k].atom), pos.prefetch(halves[k].partner);
      __builtin_prefetch(reach + halves[k].atom, 0, 3);
    }
    // minimum_image's shortcut, decided here for x and y together: per axis the limit of twice
    // |d| (the length on an axis that wraps, inf on one that does not, -1 - never - where the
    // length is inf) and what the shortcut adds (+0.0 where the axis wraps; -0.0, which changes
    // no double, where it does not). A half off the shortcut goes through half_bond_end itself.
    double limit[3], add[3];
    for (int a = 0; a < 3; ++a) {
      const bool wraps = box && box->periodic[a] && box->length[a] > 0.0;
      limit[a] = !wraps                                                 ? inf.x
                 : box->length[a] <= std::numeric_limits<double>::max() ? box->length[a]
                                                                        : -1.0;
      add[a] = wraps ? 0.0 : -0.0;
    }
    const DoublePair limit_xy = DoublePair::of(limit[0], limit[1]),
                     add_xy = DoublePair::of(add[0], add[1]);
    const DoublePair half = DoublePair::of(0.5, 0.5);
    // Halves off the shortcut, or with a partner not finite, wait in `slow` for the end of their
    // brick: the loop below then calls nothing, so its sums stay in registers. A slow half adds
    // its ends to the brick's bounds and its length to its atom's reach afterwards, which gives
    // the same bits (min, max and a maximum of lengths, as above).
    uint32_t most = 0;  // halves in a brick
    for (size_t b = 0; b < brick_count; ++b) most = std::max(most, r.first[b + 1] - r.first[b]);
    std::vector<uint32_t> slow_list(most);
    uint32_t *const slow = slow_list.data();
    for (size_t b = 0; b < brick_count && ok; ++b) {
      DoublePair lo_xy = DoublePair::of(inf.x, inf.x), hi_xy = DoublePair::of(-inf.x, -inf.x);
      double lo_z = inf.x, hi_z = -inf.x;
      const uint32_t last = r.first[b + 1];
      uint32_t slow_count = 0;
      for (uint32_t k = r.first[b]; k < last;) {
        const uint32_t atom = halves[k].atom;
        const glm::dvec3 x = pos.get(atom);
        if (!finite_position(x)) return void(ok = false);
        const DoublePair x_xy = DoublePair::of(x.x, x.y);
        lo_xy = lo_xy.min(x_xy), hi_xy = hi_xy.max(x_xy);
        lo_z = glm::min(lo_z, x.z), hi_z = glm::max(hi_z, x.z);
        double longest = 0.0;  // squared
        for (; k < last && halves[k].atom == atom; ++k) {
          if (k + kAhead < count) {
            // The atom (and its reach) only where a run starts: the others are its run's.
            const HalfBond &ahead = halves[k + kAhead];
            pos.prefetch(ahead.partner);
            if (ahead.atom != halves[k + kAhead - 1].atom)
              pos.prefetch(ahead.atom), __builtin_prefetch(reach + ahead.atom, 0, 3);
          }
          const glm::dvec3 partner = pos.get(halves[k].partner);
          // half_bond_end: x + 0.5 * minimum_image(partner - x). The shortcut's test fails for
          // a NaN; an infinite partner (passing it on an axis that does not wrap) goes slow too.
          const DoublePair d_xy = DoublePair::of(partner.x, partner.y) - x_xy;
          const double d_z = partner.z - x.z;
          if (!(d_xy.twice_within(limit_xy) && 2.0 * std::abs(d_z) <= limit[2]) ||
              !(std::abs(d_z) <= std::numeric_limits<double>::max() && d_xy.finite())) {
            slow[slow_count++] = k;
            continue;
          }
          const DoublePair end_xy = x_xy + half * (d_xy + add_xy);
          const double end_z = x.z + 0.5 * (d_z + add[2]);
          lo_xy = lo_xy.min(end_xy), hi_xy = hi_xy.max(end_xy);
          lo_z = glm::min(lo_z, end_z), hi_z = glm::max(hi_z, end_z);
          // glm::dot(end - x, end - x): (x * x + y * y) + z * z.
          const DoublePair along = end_xy - x_xy, square = along * along;
          const double along_z = end_z - x.z;
          longest = std::max(longest, square.x() + square.y() + along_z * along_z);
        }
        // An owned atom's halves are one run (its own, filed under it), and its reach was just
        // cleared to +0: the root is its reach, written without reading the entry first (a
        // cache miss the loop would wait on). A ghost's halves may lie in several runs.
        const double run_reach = root_of_square(longest);
        if (atom < owned)
          reach[atom] = run_reach;
        else
          reach[atom] = std::max(reach[atom], run_reach);
      }
      glm::dvec3 lo(lo_xy.x(), lo_xy.y(), lo_z), hi(hi_xy.x(), hi_xy.y(), hi_z);
      for (uint32_t j = 0; j < slow_count; ++j) {
        const uint32_t k = slow[j];
        const glm::dvec3 x = pos.get(halves[k].atom), partner = pos.get(halves[k].partner);
        if (!finite_position(partner)) return void(ok = false);
        const glm::dvec3 end = half_bond_end(x, partner, box);
        lo = glm::min(lo, end), hi = glm::max(hi, end);
        const glm::dvec3 along = end - x;
        double &atom_reach = reach[halves[k].atom];
        atom_reach = std::max(atom_reach, std::sqrt(glm::dot(along, along)));
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
