// Splits a frame's atoms over lantern-imd's ranks by where they are: along the z-order (Morton)
// curve over the frame's bounds, in parts of nearly equal count. Each rank then renders a compact
// region, as a domain-decomposed simulation's ranks would, rather than atoms scattered over the
// whole box (images do not depend on the split; compositing and culling work less with compact
// parts).
//
// Cost: O(n) with a counting sort on the key's top 18 bits (an octree of depth 6); the parts'
// sizes differ by at most the atoms of one such cell. Atoms with a non-finite coordinate go to
// part 0 (Lantern skips and counts them). Reuses its buffers from frame to frame.
// Thread-safety: one thread per object.
#pragma once

#include <cstdint>
#include <vector>

namespace lantern_imd {

class SpatialSplit {
 public:
  // Splits atoms xyz[0 .. 3n) into `parts`; then counts(), offsets() and order() describe it.
  void split(const float *xyz, int64_t n, int parts);
  const std::vector<int> &counts() const { return counts_; }    // atoms of each part
  const std::vector<int> &offsets() const { return offsets_; }  // where each part starts
  const std::vector<int32_t> &order() const { return order_; }  // atom indices, part by part

 private:
  std::vector<int64_t> cell_count_;  // atoms per cell
  std::vector<int32_t> cell_of_;     // each atom's cell
  std::vector<int> part_of_cell_;
  std::vector<int> counts_, offsets_;
  std::vector<int32_t> order_;
};

}  // namespace lantern_imd
