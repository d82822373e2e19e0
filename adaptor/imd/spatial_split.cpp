#include "spatial_split.h"

#include <cmath>
#include <limits>

#include "core/bricks/morton.h"

namespace lantern_imd {
namespace {

constexpr int kCellBits = 18;  // the key's top bits: an octree of depth 6
constexpr int kCells = 1 << kCellBits;

bool finite(const float *p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

}  // namespace

void SpatialSplit::split(const float *xyz, int64_t n, int parts) {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()}, hi{-lo};
  for (int64_t i = 0; i < n; ++i) {
    const float *p = xyz + 3 * i;
    if (!finite(p)) continue;
    for (int a = 0; a < 3; ++a)
      lo[a] = std::min(lo[a], double(p[a])), hi[a] = std::max(hi[a], double(p[a]));
  }
  const auto q = lantern::MortonQuantiser::for_bounds(lo, hi);
  cell_count_.assign(kCells, 0);
  cell_of_.resize(size_t(n));
  for (int64_t i = 0; i < n; ++i) {
    const float *p = xyz + 3 * i;
    const int32_t cell = finite(p) ? int32_t(q.key(glm::dvec3(p[0], p[1], p[2])) >>
                                             (3 * lantern::kMortonBitsPerAxis - kCellBits))
                                   : 0;
    cell_of_[size_t(i)] = cell;
    ++cell_count_[size_t(cell)];
  }
  // Part r takes the cells up to where the running count reaches (r + 1) n / parts.
  part_of_cell_.resize(kCells);
  counts_.assign(size_t(parts), 0);
  int64_t running = 0;
  int part = 0;
  for (int c = 0; c < kCells; ++c) {
    while (part < parts - 1 && running >= (part + 1) * n / parts) ++part;
    part_of_cell_[size_t(c)] = part;
    counts_[size_t(part)] += int(cell_count_[size_t(c)]);
    running += cell_count_[size_t(c)];
  }
  offsets_.assign(size_t(parts), 0);
  for (int r = 1; r < parts; ++r)
    offsets_[size_t(r)] = offsets_[size_t(r - 1)] + counts_[size_t(r - 1)];
  // Counting sort by part (stable: each part keeps the stream's order).
  std::vector<int> next = offsets_;
  order_.resize(size_t(n));
  for (int64_t i = 0; i < n; ++i)
    order_[size_t(next[size_t(part_of_cell_[size_t(cell_of_[size_t(i)])])]++)] = int32_t(i);
}

}  // namespace lantern_imd
