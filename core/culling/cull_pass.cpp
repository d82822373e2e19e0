#include "core/culling/cull_pass.h"

#include <algorithm>
#include <array>
#include <limits>

#include <glm/common.hpp>

#include "core/common/double_pair.h"

namespace lantern {
namespace {

// A brick's candidates go to cells: kSlabs slabs of depth, nearest first, each split in
// kSide x kSide by view x and y. Depth slabs alone give boxes as wide as the brick, which at a
// surface seen at a slant always hold some particle that shows, so their box test rarely hides
// anything; cut across, the cells behind the front are hidden by one test. Eight slabs (16
// before): since a sphere's own test reads its few rows of depth directly (cpu_sphere_raster.h),
// a cell's box test costs about as much as the tests it saves, and fewer, fuller cells cost less
// (1 M-atom LJ frame: about 0.7 ms less cull + draw of 18-19 ms, 4 % more spheres drawn; fcc and
// heterogeneous 10 M: 1-4 ms less of 60 and 115; tests/bench/culling/results/base_rows_ab.txt).
constexpr int kSlabs = 8;
constexpr int kSide = 2;
constexpr int kCells = kSlabs * kSide * kSide;

// The scale that maps [lo, hi] onto cells [0, n) (with a clamp of the top end): 0 when the range
// is empty, or too narrow for n / (hi - lo) to be finite (a width below about n / DBL_MAX, as
// denormal coordinates give): an infinite scale made 0 x inf = NaN of the lowest candidate's
// offset, and a cell index of INT_MIN.
double cell_scale(double lo, double hi, int n) {
  const double scale = hi > lo ? n / (hi - lo) : 0.0;
  return scale <= std::numeric_limits<double>::max() ? scale : 0.0;
}

// Running bounds of points or spheres, a bound moving only to a value strictly beyond it (as
// glm::min and glm::max have it): x and y as one DoublePair (half the instructions of glm's
// component by component with SSE2), the same values.
class RunningBounds {
 public:
  void add(const glm::dvec3 &p) { grow(DoublePair::load(&p.x), p.z, DoublePair::load(&p.x), p.z); }
  void add(const glm::dvec3 &c, double r) {
    const DoublePair xy = DoublePair::load(&c.x), rr = DoublePair::of(r, r);
    grow(xy - rr, c.z - r, xy + rr, c.z + r);
  }
  void add(const RunningBounds &o) { grow(o.lo_xy_, o.lo_z_, o.hi_xy_, o.hi_z_); }
  glm::dvec3 lo() const { return {lo_xy_.x(), lo_xy_.y(), lo_z_}; }
  glm::dvec3 hi() const { return {hi_xy_.x(), hi_xy_.y(), hi_z_}; }

 private:
  void grow(DoublePair lo_xy, double lo_z, DoublePair hi_xy, double hi_z) {
    lo_xy_ = lo_xy_.min(lo_xy), hi_xy_ = hi_xy_.max(hi_xy);
    lo_z_ = lo_z < lo_z_ ? lo_z : lo_z_, hi_z_ = hi_z_ < hi_z ? hi_z : hi_z_;
  }
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  DoublePair lo_xy_ = DoublePair::of(kInf, kInf), hi_xy_ = DoublePair::of(-kInf, -kInf);
  double lo_z_ = kInf, hi_z_ = -kInf;
};

}  // namespace

void order_front_to_back(CandidateBuffers *b) {
  const UninitializedBuffer<Candidate> &in = b->gathered;
  UninitializedBuffer<Candidate> &out = b->sorted;
  std::vector<DepthBucket> &buckets = b->buckets;
  out.resize(in.size());
  buckets.clear();
  if (in.empty()) return;
  const size_t count = in.size();
  // Two candidates a step, each into its own bounds: minima and maxima are exact in any order, and
  // two chains of them wait out half the latency of one.
  RunningBounds even, odd_bounds;
  size_t j = 0;
  for (; j + 2 <= count; j += 2) even.add(in[j].c), odd_bounds.add(in[j + 1].c);
  if (j < count) even.add(in[j].c);
  even.add(odd_bounds);
  const glm::dvec3 lo = even.lo(), hi = even.hi();
  // Depth -z grows from -hi.z.
  const double sx = cell_scale(lo.x, hi.x, kSide), sy = cell_scale(lo.y, hi.y, kSide);
  const double sz = cell_scale(-hi.z, -lo.z, kSlabs);
  const auto cell = [&](const Candidate &c) {
    // offset * scale lies in [0, n]: a signed conversion (one instruction) is exact for it.
    const auto index = [](double offset, double scale, int n) {
      return std::min(int(offset * scale), n - 1);
    };
    const int ix = index(c.c.x - lo.x, sx, kSide), iy = index(c.c.y - lo.y, sy, kSide);
    return (index(hi.z - c.c.z, sz, kSlabs) * kSide + iy) * kSide + ix;
  };
  // Each candidate's cell, found once for the count and the scatter. Neighbours mostly share a
  // cell: two tallies, even and odd candidates, so that one count's increments do not wait on
  // each other through memory.
  static_assert(kCells <= 256, "a cell fits a byte");
  std::vector<uint8_t> &cells = b->cells;
  cells.resize(count);
  std::array<uint32_t, kCells + 1> counts{}, odd{};
  for (j = 0; j + 2 <= count; j += 2) {
    const int k0 = cell(in[j]), k1 = cell(in[j + 1]);
    cells[j] = uint8_t(k0), cells[j + 1] = uint8_t(k1);
    ++counts[size_t(k0) + 1], ++odd[size_t(k1) + 1];
  }
  if (j < count) {
    const int k = cell(in[j]);
    cells[j] = uint8_t(k);
    ++counts[size_t(k) + 1];
  }
  for (size_t k = 1; k < counts.size(); ++k) counts[k] += odd[k] + counts[k - 1];
  // The non-empty cells, nearest slab first, before the scatter moves their starts.
  for (size_t k = 0; k < kCells; ++k)
    if (counts[k + 1] > counts[k]) {
      // Written in place: a bucket built aside and copied in was read back before its stores
      // had landed (a stall a bucket).
      DepthBucket &d = buckets.emplace_back();
      d.begin = counts[k], d.end = counts[k + 1];
    }
  std::array<uint32_t, kCells + 1> &slot = counts;
  for (j = 0; j < count; ++j) out[slot[cells[j]]++] = in[j];
  // Each cell's box once its candidates lie together, its bounds in registers: grown during the
  // scatter they chained every candidate's minima and maxima through memory. Minima and maxima do
  // not depend on the order, so every box is the one the scatter grew. With the bounds two at a
  // time, x and y together, the counts in two tallies and the buckets written in place, this
  // function takes 1.09 ms of a rank's frame on the 1 M-atom LJ melt against 1.28 before (perf,
  // medians of 7 alternated runs; tests/bench/culling/results/order_front_to_back_ab.txt).
  for (DepthBucket &d : buckets) {
    RunningBounds box, box_odd;
    uint32_t k = d.begin;
    for (; k + 2 <= d.end; k += 2)
      box.add(out[k].c, out[k].r), box_odd.add(out[k + 1].c, out[k + 1].r);
    if (k < d.end) box.add(out[k].c, out[k].r);
    box.add(box_odd);
    d.lo = box.lo(), d.hi = box.hi();
    // -c.z - r rounds to -(c.z + r): negation commutes with rounding to nearest.
    d.near = -d.hi.z;
  }
}

}  // namespace lantern
