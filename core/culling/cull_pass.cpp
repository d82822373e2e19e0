#include "core/culling/cull_pass.h"

#include <algorithm>
#include <array>
#include <limits>

#include <glm/common.hpp>

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
// is empty.
double cell_scale(double lo, double hi, int n) {
  return hi > lo ? n / (hi - lo) : 0.0;
}

}  // namespace

void order_front_to_back(CandidateBuffers *b) {
  const UninitializedBuffer<Candidate> &in = b->gathered;
  UninitializedBuffer<Candidate> &out = b->sorted;
  std::vector<DepthBucket> &buckets = b->buckets;
  out.resize(in.size());
  buckets.clear();
  if (in.empty()) return;
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Candidate &c : in) lo = glm::min(lo, c.c), hi = glm::max(hi, c.c);
  // Depth -z grows from -hi.z.
  const double sx = cell_scale(lo.x, hi.x, kSide), sy = cell_scale(lo.y, hi.y, kSide);
  const double sz = cell_scale(-hi.z, -lo.z, kSlabs);
  const auto cell = [&](const Candidate &c) {
    const auto index = [](double offset, double scale, int n) {
      return std::min(size_t(offset * scale), size_t(n - 1));
    };
    const size_t ix = index(c.c.x - lo.x, sx, kSide), iy = index(c.c.y - lo.y, sy, kSide);
    return (index(hi.z - c.c.z, sz, kSlabs) * kSide + iy) * kSide + ix;
  };
  std::vector<uint32_t> &counts = b->bucket_counts;
  counts.assign(kCells + 1, 0);
  // Each candidate's cell, found once for the count and the scatter.
  static_assert(kCells <= 256, "a cell fits a byte");
  std::vector<uint8_t> &cells = b->cells;
  cells.resize(in.size());
  for (size_t j = 0; j < in.size(); ++j) cells[j] = uint8_t(cell(in[j]));
  for (const uint8_t k : cells) ++counts[size_t(k) + 1];
  for (size_t k = 1; k < counts.size(); ++k) counts[k] += counts[k - 1];
  // The non-empty cells, nearest slab first; which[k]: cell k's place among them.
  std::array<uint32_t, kCells> which{};
  for (size_t k = 0; k < kCells; ++k)
    if (counts[k + 1] > counts[k]) {
      which[k] = uint32_t(buckets.size());
      DepthBucket d;
      d.begin = counts[k], d.end = counts[k + 1];
      d.lo = glm::dvec3(std::numeric_limits<double>::infinity()), d.hi = -d.lo;
      d.near = std::numeric_limits<double>::infinity();
      buckets.push_back(d);
    }
  // Scatter into the cells, growing each one's box.
  std::vector<uint32_t> &slot = counts;
  for (size_t j = 0; j < in.size(); ++j) {
    const Candidate &c = in[j];
    const size_t k = cells[j];
    DepthBucket &d = buckets[which[k]];
    d.lo = glm::min(d.lo, c.c - c.r), d.hi = glm::max(d.hi, c.c + c.r);
    d.near = std::min(d.near, -c.c.z - c.r);
    out[slot[k]++] = c;
  }
}

}  // namespace lantern
