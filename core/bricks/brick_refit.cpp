#include "core/bricks/brick_set.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include <glm/common.hpp>

#include "core/bricks/brick_steps.h"
#include "core/bricks/index_runs.h"
#include "core/bricks/level_layout.h"
#include "core/bricks/morton.h"
#include "core/bricks/radix_sort.h"
#include "core/common/page_allocator.h"
#include "core/common/rank_threads.h"
#include "core/particles/typed_access.h"

namespace lantern {

using namespace brick_steps;

// Here, with the refit: spread() is what refit_bricks's max_growth limits; build_bricks records
// its value at build (spread_at_build) for that comparison.
double BrickSet::spread() const {
  double s = 0.0;
  for (const Brick &b : bricks) s += (b.hi.x - b.lo.x) + (b.hi.y - b.lo.y) + (b.hi.z - b.lo.z);
  return s;
}

namespace {

// How far a brick's particles may move beyond its last bounds and stay in it: a quarter of its
// size on each axis, and at least a quarter of the mean brick edge at build (`floor`). Without
// the floor, a brick that is thin on some axis lost its particles at every step: the strays of a
// host's re-neighbouring (atoms wrapped through a periodic face or migrated from another rank)
// lie on planes, so the bricks they are sorted into are plates a few hundredths of an atom
// thick, and a brick that loses a particle sends the whole refit down its slow path (moving
// every slice, listing the runs again): on the 1 M-atom LAMMPS melt, 3.1-3.9 ms a refit instead
// of 1.3-1.6 from the first re-neighbouring on, for one to nine such plates a step.
glm::dvec3 slack(const Brick &b, double floor) {
  return glm::max(0.25 * (b.hi - b.lo), glm::dvec3(floor));
}

// The box a particle of brick `b` must stay in at a refit's slow path: its last bounds grown by
// its slack (floor: slack()) and a relative 1e-9. Both ways of sorting out (sort_out,
// sort_out_through_runs) test against it, so they keep the same particles.
struct Box {
  glm::dvec3 lo, hi;
  // Branch-free (no short-circuits): one branch at the caller, taken for the rare stray.
  bool holds(const glm::dvec3 &x) const {
    return (x.x >= lo.x) & (x.y >= lo.y) & (x.z >= lo.z) & (x.x <= hi.x) & (x.y <= hi.y) &
           (x.z <= hi.z);
  }
};
Box stay_box(const Brick &b, double floor) {
  const glm::dvec3 grow = slack(b, floor) + 1e-9 * (glm::abs(b.lo) + glm::abs(b.hi));
  return {b.lo - grow, b.hi + grow};
}

// Keeps, in place and in order at the front of the brick's slice `seg`, the particles of `b`
// that are still published (index below `count`, and in the group: `keep`) and inside the brick's
// last bounds grown by its slack (floor: slack()), and gives *b their count and bounds; the others
// go to `outliers`. False if a particle is not finite.
template <typename Positions, typename Radii, typename Keep>
bool sort_out(const Positions &pos, const Radii &radius, const Keep &keep, bool has_radius,
              int64_t count, double floor, uint32_t *seg, Brick *b,
              std::vector<uint32_t> *outliers) {
  const Box box = stay_box(*b, floor);
  glm::dvec3 new_lo(std::numeric_limits<double>::infinity()), new_hi(-new_lo);
  double r = 0.0;
  uint32_t kept = 0;
  for (uint32_t k = 0; k < b->count; ++k) {
    const uint32_t i = seg[k];
    if (int64_t(i) >= count || !keep.get(i)) continue;  // no longer published, or left the group
    const glm::dvec3 x = pos.get(i);
    if (!finite(x)) return false;
    if (box.holds(x)) {
      seg[kept++] = i;
      new_lo = glm::min(new_lo, x), new_hi = glm::max(new_hi, x);
      if (has_radius) r = std::max(r, radius.get(i));
    } else {
      outliers->push_back(i);
    }
  }
  b->count = kept, b->lo = new_lo, b->hi = new_hi, b->max_radius = r;
  return true;
}

// What one part of a refit's slow path sorted out: the strays it found, and whether every
// position it read was finite.
struct SortedOut {
  std::vector<uint32_t> outliers;
  bool finite = true;
  uint64_t *stray = nullptr;  // sort_out_through_runs: a bit per index, set for each stray
};

// The particles of one brick in run [first, last): all of them (bits null), or those whose
// in_other bit is `in_other`, in index order. Those in the group and inside `box` widen the
// bounds in *s; the others in the group are strays: into h->outliers and marked in h->stray.
// False if a position is not finite. The bounds stay in registers for the stretch, and a
// two-brick run's particles are picked from the bits 64 at a time, as scan_stretch does (a
// branch on each particle's bit would mispredict: the bricks' particles interleave).
template <typename Positions, typename Radii, typename Keep>
bool sort_stretch(const Positions &pos, const Radii &radius, const Keep &keep, bool has_radius,
                  const uint64_t *bits, bool in_other, int64_t first, int64_t last, const Box &box,
                  BrickScan *s, SortedOut *h) {
  double lx = s->lo.x, ly = s->lo.y, lz = s->lo.z, hx = s->hi.x, hy = s->hi.y, hz = s->hi.z;
  double r = s->r;
  const auto one = [&](int64_t i) {
    if (!keep.get(i)) return true;
    const glm::dvec3 x = pos.get(i);
    if (!finite(x)) return false;
    if (box.holds(x)) {
      lx = x.x < lx ? x.x : lx, ly = x.y < ly ? x.y : ly, lz = x.z < lz ? x.z : lz;
      hx = hx < x.x ? x.x : hx, hy = hy < x.y ? x.y : hy, hz = hz < x.z ? x.z : hz;
      if (has_radius) r = std::max(r, radius.get(i));
    } else {
      h->outliers.push_back(uint32_t(i));
      h->stray[size_t(i >> 6)] |= uint64_t(1) << (i & 63);
    }
    return true;
  };
  bool ok = true;
  if (!bits) {
    for (int64_t i = first; i < last && ok; ++i) ok = one(i);
  } else {
    for (int64_t w = first >> 6; w <= (last - 1) >> 6 && ok && first < last; ++w) {
      const int64_t base = w * 64;
      uint64_t word = in_other ? bits[w] : ~bits[w];
      if (base < first) word &= ~uint64_t(0) << (first - base);
      if (base + 64 > last) word &= ~uint64_t(0) >> (base + 64 - last);
      while (word != 0 && ok) {
        ok = one(base + __builtin_ctzll(word));
        word &= word - 1;
      }
    }
  }
  s->lo = {lx, ly, lz}, s->hi = {hx, hy, hz}, s->r = r;
  return ok;
}

// How many runs ahead sort_out_through_runs asks for the positions it will read: about 170
// particles, 4 KiB of packed doubles. Why: it reads only the runs of bricks that lost particles,
// a few lines here and there, which the processor's own prefetcher does not foresee.
constexpr size_t kSortAhead = 16;

// The next run of *ahead asked for into the cache where sort_out_through_runs will read it (one
// of its bricks does not fit).
template <typename Positions>
void ask_for_run(const Positions &pos, const std::vector<uint8_t> &fits, IndexRuns::Reader *ahead) {
  uint32_t first, stop, brick, other;
  ahead->next(&first, &stop, &brick, &other);
  if (brick == kNoBrick || (fits[brick] && (other == kNoBrick || fits[other]))) return;
  for (uint32_t i = first; i < stop; i += 2) pos.prefetch(i);
  pos.prefetch(stop - 1);
}

// sort_out for every brick that does not fit (fits[b] == 0), reading the positions through the
// set's runs in index order instead of brick by brick in each brick's order. Why: a brick's order
// is its level layout (uniform samples first), so sort_out reads its few dozen stretches of the
// host's arrays back and forth; on the 1 M-atom LAMMPS melt with an image every 100 steps, 42 %
// of the particles are in bricks that lost some, and sort_out took 2.3-5.0 ms of a 9-11 ms refit
// (about 20 ns a particle), this 1.9-3.3 ms (throwaway timers, the same frames; asking for the
// positions 48 runs ahead rather than kSortAhead gained nothing). Here a first pass streams the
// runs of those bricks, tests each particle against its brick's stay_box (as sort_out does), sums
// the bounds of those that stay and marks those that leave in a bit per index; a second pass closes
// each brick's slice over the marked indices without reading a position. The same particles stay,
// in the same order, with the same bounds: min and max visit them in another order, which can
// change only the sign of a zero bound, and such a brick is bounded again in its own order. The
// strays come in index order rather than brick by brick; refit_bricks sorts them by (key, index),
// so their order does not matter. `scans`: the refit's fresh bounds, one per brick, overwritten for
// the bricks that do not fit. Parts cut the runs at blocks of indices (a multiple of 64: no two
// parts write one word of the marks); part p's strays in (*parts)[p].
template <typename Positions, typename Radii, typename Keep>
void sort_out_through_runs(const Positions &pos, const Radii &radius, const Keep &keep,
                           int64_t count, const std::vector<uint8_t> &fits,
                           PageVector<BrickScan> *scans, BrickSet *set,
                           std::vector<SortedOut> *parts) {
  const IndexRuns &runs = set->runs;
  const double floor = 0.25 * set->mean_edge_at_build;
  const bool has_radius = set->has_radius;
  const int64_t listed = runs.back().first;
  PageVector<uint64_t> stray(static_cast<size_t>((listed + 63) / 64), 0);
  const size_t bricks = set->bricks.size(), blocks = runs.blocks();
  const size_t stretches = runs.size() - 1;
  const int count_parts = int(parts->size());
  // Part 0 sums into *scans; the others into their own, added after in part order.
  std::vector<PageVector<BrickScan>> own(static_cast<size_t>(std::max(0, count_parts - 1)));
  for (size_t b = 0; b < bricks; ++b)
    if (!fits[b]) (*scans)[b] = BrickScan{};
  const uint64_t *bits = set->in_other.data();
  const auto grown = [&](uint32_t b) { return stay_box(set->bricks[b], floor); };
  run_in_parts(count_parts, int64_t(blocks), [&](int p, int64_t b0, int64_t b1) {
    BrickScan *acc = scans->data();
    if (p > 0) {
      PageVector<BrickScan> &mine = own[size_t(p - 1)];
      mine.assign(bricks, BrickScan{});
      acc = mine.data();
    }
    SortedOut &h = (*parts)[size_t(p)];
    h.stray = stray.data();
    const auto block_stretch = [&](int64_t b) {
      return size_t(b) < blocks ? size_t(runs.block_start(size_t(b))) : stretches;
    };
    const size_t begin = block_stretch(b0), end = block_stretch(b1);
    IndexRuns::Reader reader(runs, begin), ahead(runs, begin);
    const size_t asked = std::min(end, begin + kSortAhead);
    for (size_t k = begin; k < asked; ++k) ask_for_run(pos, fits, &ahead);
    for (size_t k = begin; k < end && h.finite; ++k) {
      if (k + kSortAhead < end) ask_for_run(pos, fits, &ahead);
      uint32_t first, stop, brick, other;
      reader.next(&first, &stop, &brick, &other);
      if (brick == kNoBrick) continue;
      const int64_t last = std::min<int64_t>(stop, count);  // later indices: no longer published
      if (other == kNoBrick) {
        if (!fits[brick])
          h.finite = sort_stretch(pos, radius, keep, has_radius, nullptr, false, first, last,
                                  grown(brick), &acc[brick], &h);
        continue;
      }
      if (!fits[brick])
        h.finite = sort_stretch(pos, radius, keep, has_radius, bits, false, first, last,
                                grown(brick), &acc[brick], &h);
      if (!fits[other] && h.finite)
        h.finite = sort_stretch(pos, radius, keep, has_radius, bits, true, first, last,
                                grown(other), &acc[other], &h);
    }
  });
  for (const SortedOut &h : *parts)
    if (!h.finite) return;
  for (const PageVector<BrickScan> &mine : own)
    for (size_t b = 0; b < bricks; ++b) {
      if (fits[b]) continue;
      BrickScan &a = (*scans)[b];
      a.lo = glm::min(a.lo, mine[b].lo), a.hi = glm::max(a.hi, mine[b].hi);
      a.r = std::max(a.r, mine[b].r);
    }
  // Each slice closed over what left or is no longer published or in the group, in its order.
  run_in_parts(count_parts, int64_t(bricks), [&](int, int64_t first, int64_t last) {
    for (int64_t k = first; k < last; ++k) {
      if (fits[size_t(k)]) continue;
      Brick &b = set->bricks[size_t(k)];
      uint32_t *seg = set->order.data() + b.first;
      uint32_t kept = 0;
      for (uint32_t j = 0; j < b.count; ++j) {
        const uint32_t i = seg[j];
        if (int64_t(i) >= count || !keep.get(i) || (stray[i >> 6] >> (i & 63) & 1)) continue;
        seg[kept++] = i;
      }
      b.count = kept;
      const BrickScan &s = (*scans)[size_t(k)];
      if (kept > 0 && has_zero_bound(s))
        bound_brick(pos, radius, has_radius, seg, kept, &b);
      else
        b.lo = s.lo, b.hi = s.hi, b.max_radius = s.r;
    }
  });
}

// Brick `b`'s particles with index below `count` and in the group, gathered in the brick's order.
template <typename Positions, typename Radii, typename Keep>
BrickScan scan_brick(const Positions &pos, const Radii &radius, const Keep &keep, int64_t count,
                     const BrickSet &set, size_t b) {
  BrickScan s;
  const Brick &br = set.bricks[b];
  const uint32_t *idx = set.order.data() + br.first;
  for (uint32_t j = 0; j < br.count; ++j) {
    if (int64_t(idx[j]) >= count || !keep.get(idx[j])) {
      s.all_published = false;
      continue;
    }
    const glm::dvec3 x = pos.get(idx[j]);
    s.finite &= (x.x - x.x == 0.0) & (x.y - x.y == 0.0) & (x.z - x.z == 0.0);
    s.lo = glm::min(s.lo, x), s.hi = glm::max(s.hi, x);
    if (set.has_radius) s.r = std::max(s.r, radius.get(idx[j]));
  }
  return s;
}

// A brick's bounds and radius from its fresh scan.
void take_bounds(const BrickScan &s, Brick *b) {
  b->lo = s.lo, b->hi = s.hi, b->max_radius = s.r;
}

// First pass of a refit: each brick's bounds over its particles with index below `count` and in
// the group, and whether the brick still fits - every index below `count` and in the group, and
// the new bounds finite and inside the old ones grown by their slack (the common case between two
// host re-neighbourings). A brick that fits takes its new bounds at once, whatever the others do
// (a brick that does not keeps its old ones, which sort_out grows); in the same loop, so that the
// 64 bytes of a brick and of its scan are read once while in cache (at 19 M fcc particles a
// rank's 131 k bricks and their scans are 16 MiB, beyond L2: a loop that tested, then one that
// took the bounds, then two over the bricks for their union and spread, cost 5.7 ms of a 63 ms
// refit). Streams the positions through the set's runs where it has them, else gathers brick by
// brick; the bounds are the same bits either way (index_runs.h). `tap` (may be null) gets the
// positions as they stream, where scan_runs hands them on. *all_fit: whether every brick fits.
template <typename Positions, typename Radii, typename Keep>
void fresh_bounds(const Positions &pos, const Radii &radius, const Keep &keep, int64_t count,
                  int threads, PositionTap *tap, BrickSet *set, PageVector<BrickScan> *bounds,
                  std::vector<uint8_t> *fits, bool *all_fit) {
  fits->assign(set->bricks.size(), 0);
  bounds->clear();
  if (!set->runs.empty())
    *bounds = scan_runs(pos, radius, keep, set->has_radius, count, *set, threads, tap);
  const bool streamed = !bounds->empty();
  if (!streamed) bounds->resize(set->bricks.size());
  const int parts = parts_for(threads, set->particle_count(), kParticlesPerThread);
  std::vector<uint8_t> part_fits(static_cast<size_t>(parts), 1);
  run_in_parts(parts, int64_t(set->bricks.size()), [&](int p, int64_t first, int64_t last) {
    bool every = true;
    for (int64_t k = first; k < last; ++k) {
      const size_t b = size_t(k);
      BrickScan &s = (*bounds)[b];
      if (!streamed || has_zero_bound(s)) s = scan_brick(pos, radius, keep, count, *set, b);
      Brick &old = set->bricks[b];
      const glm::dvec3 grow = slack(old, 0.25 * set->mean_edge_at_build);
      // Written so that NaN (a NaN bound) fails the test.
      const bool inside = s.lo.x >= old.lo.x - grow.x && s.lo.y >= old.lo.y - grow.y &&
                          s.lo.z >= old.lo.z - grow.z && s.hi.x <= old.hi.x + grow.x &&
                          s.hi.y <= old.hi.y + grow.y && s.hi.z <= old.hi.z + grow.z &&
                          std::isfinite(s.r) && s.finite;
      const bool fit = s.all_published && inside;
      (*fits)[b] = fit;
      every &= fit;
      if (fit) take_bounds(s, &old);
    }
    part_fits[size_t(p)] = every;
  });
  *all_fit = std::find(part_fits.begin(), part_fits.end(), 0) == part_fits.end();
}

}  // namespace

bool refit_bricks(const ParticleArrays &particles, double max_growth, BrickSet *set,
                  const BrickOptions &options) {
  set->generation = next_brick_generation();  // the bounds change below, whatever the outcome
  const uint64_t kept_order = std::exchange(set->order_generation, set->generation);
  const int64_t count = particles.count();
  const int threads = std::max(1, options.threads);
  if (set->nonfinite != 0 || particles.has_radius() != set->has_radius ||
      count >= (int64_t(1) << 32) || count == 0)
    return false;
  // With a group, the bricks must end up holding exactly its members: a particle that joined the
  // group under an index the bricks do not hold makes the count differ, and a rebuild follows.
  const int64_t kept_total = particles.kept_count();
  // The new bounds stay in the scans until the bricks take them (no copy of the bricks).
  PageVector<BrickScan> fresh;
  std::vector<uint8_t> fits;
  bool all_fit = false;
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, true, 0.0, [&](const auto &radius) {
      visit_kept(particles, [&](const auto &keep) {
        fresh_bounds(pos, radius, keep, count, threads, options.tap, set, &fresh, &fits, &all_fit);
      });
    });
  });
  if (kept_total == set->particle_count() && all_fit) {
    set->order_generation = kept_order;  // every particle stayed in its slot
    // The union and spread() in one pass over the bricks (the spread summed in the same order,
    // so the same bits).
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
    double spread = 0.0;
    for (const Brick &b : set->bricks) {
      lo = glm::min(lo, b.lo), hi = glm::max(hi, b.hi);
      spread += (b.hi.x - b.lo.x) + (b.hi.y - b.lo.y) + (b.hi.z - b.lo.z);
    }
    set->lo = lo, set->hi = hi;
    set->spread_now = spread;
    return spread <= max_growth * set->spread_at_build;
  }
  const int64_t known = set->particle_count();
  // Each part of the bricks (one per thread) sorts out its strays in place; their lists are joined
  // in part order, so the result does not depend on the thread count.
  const int parts = parts_for(threads, known, kParticlesPerThread);
  std::vector<SortedOut> part(static_cast<size_t>(parts));
  std::vector<uint32_t> outliers;
  bool finite_all = true;
  size_t kept_bricks = 0;
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, true, 0.0, [&](const auto &radius) {
      visit_kept(particles, [&](const auto &keep) {
        // Particles that left their brick (moved far, wrapped through a periodic boundary, or an
        // index the host now uses for another particle) and new indices become outliers.
        if (!set->runs.empty())
          sort_out_through_runs(pos, radius, keep, count, fits, &fresh, set, &part);
        else
          run_in_parts(parts, int64_t(set->bricks.size()), [&](int p, int64_t first, int64_t last) {
            SortedOut &h = part[size_t(p)];
            for (int64_t k = first; k < last && h.finite; ++k) {
              Brick &br = set->bricks[size_t(k)];
              if (!fits[size_t(k)])  // one that fits took its new bounds in fresh_bounds
                h.finite = sort_out(pos, radius, keep, set->has_radius, count,
                                    0.25 * set->mean_edge_at_build, set->order.data() + br.first,
                                    &br, &h.outliers);
            }
          });
        for (const SortedOut &h : part)
          if (!h.finite) {
            finite_all = false;
            return;
          }
        // Close the gaps the strays left: kept slices move down, empty bricks go.
        uint32_t at = 0;
        size_t out = 0;
        for (const Brick &br : set->bricks) {
          if (br.count == 0) continue;
          Brick moved = br;
          std::memmove(set->order.data() + at, set->order.data() + br.first,
                       size_t(br.count) * sizeof(uint32_t));
          moved.first = at;
          at += br.count;
          set->bricks[out++] = moved;
        }
        set->bricks.resize(out);
        set->order.resize(at);
        kept_bricks = out;
        for (SortedOut &h : part) {
          outliers.insert(outliers.end(), h.outliers.begin(), h.outliers.end());
          std::vector<uint32_t>().swap(h.outliers);
        }
        for (int64_t i = known; i < count; ++i) {
          if (!keep.get(i)) continue;
          if (!finite(pos.get(i))) {
            finite_all = false;
            return;
          }
          outliers.push_back(uint32_t(i));
        }
        // Too many strays: a fresh build gives tighter bricks for about the same cost.
        if (outliers.size() * 10 > size_t(kept_total)) {
          finite_all = false;
          return;
        }
        if (outliers.empty()) return;
        // The strays in z-order of their own bounds, cut into octree bricks as build_bricks does.
        glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
        for (const uint32_t i : outliers)
          lo = glm::min(lo, pos.get(i)), hi = glm::max(hi, pos.get(i));
        const MortonQuantiser q = MortonQuantiser::for_bounds(lo, hi);
        PageVector<uint64_t> words(outliers.size()), scratch;
        for (size_t k = 0; k < outliers.size(); ++k)
          words[k] = make_word(q.key(pos.get(outliers[k])), outliers[k]);
        radix_sort_words(&words, &scratch, 32, 64);
        std::vector<std::pair<uint64_t, uint64_t>> run;
        break_ties(pos, q, words.data(), 0, words.size(), &run);
        std::vector<Brick> extra;
        split_cells(words.data(), 0, uint32_t(words.size()), 0,
                    std::max<uint32_t>(1, options.max_particles), &extra);
        const auto offset = uint32_t(set->order.size());
        set->order.resize(offset + words.size());
        for (Brick e : extra) {
          lay_out_brick(words.data(), e, options.level_layout, set->order.data() + offset);
          e.first += offset;
          set->bricks.push_back(e);
        }
      });
    });
  });
  if (!finite_all || set->particle_count() != kept_total) return false;
  // Particles moved between bricks: the runs are listed again (none where too short to pay).
  list_runs(count, set);
  // Kept bricks got their bounds while sorting out; the strays' bricks get theirs here.
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, true, 0.0, [&](const auto &radius) {
      for (size_t k = kept_bricks; k < set->bricks.size(); ++k) {
        Brick &b = set->bricks[k];
        bound_brick(pos, radius, set->has_radius, set->order.data() + b.first, b.count, &b);
      }
    });
  });
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  for (const Brick &b : set->bricks) {
    if (!std::isfinite(b.max_radius)) return false;
    lo = glm::min(lo, b.lo), hi = glm::max(hi, b.hi);
  }
  set->lo = lo, set->hi = hi;
  set->spread_now = set->spread();
  return set->spread_now <= max_growth * set->spread_at_build;
}

}  // namespace lantern
