// Cutting planes per brick, kept between frames so that adding, removing or toggling a plane
// reclassifies only the bricks that plane touches (the cross-sections paper, §3.1-3.4: a counter
// per block).
//
// For every brick two counters: how many of the enabled planes cut it away entirely (`dropped`),
// and how many pass through it (`crossed`). A brick is dropped when dropped > 0, needs a
// per-particle test when dropped == 0 and crossed > 0, and is kept otherwise - exactly what
// CutPlanes::classify_box says for the same planes (it runs the same per-plane test), so images
// are bit-identical to a classification from scratch. Undoing a plane decrements what adding it
// incremented; the counters need no history beyond the list of planes applied.
//
// A plane is applied through a bounding hierarchy over the bricks in z-order (built once per
// brick generation): a group of bricks wholly on the kept side of the plane is skipped as a
// whole, a group wholly on the dropped side is counted without a test per brick, and only
// groups the plane passes through are tested brick by brick. So a plane costs in proportion to
// the bricks it cuts away or crosses, not to all bricks.
//
// The counts belong to one BrickSet generation (BrickSet::generation): when the bricks are
// rebuilt or refit (new bounds), update() starts again from zero with every enabled plane.
//
// Ownership: owns its counters and hierarchy (about 8 B per brick plus 64 B per 8 bricks); refers
// to bricks by index. Thread-safety: none (one per scene, used by the pipeline's thread).
#pragma once

#include <cstdint>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/config/config.h"
#include "core/culling/cut_planes.h"

namespace lantern {

class BrickCutCounts {
 public:
  // What the last update() did, for tests and benchmarks.
  struct Update {
    bool from_scratch = false;  // counters reset (new bricks, or first use)
    int planes_added = 0;       // planes applied (+1) in this update
    int planes_removed = 0;     // planes undone (-1) in this update
    int64_t bricks_tested = 0;  // single-brick plane tests made
  };

  // Brings the counters to `cuts` (the scene's cut_planes; disabled planes count as absent) for
  // `bricks`: incrementally when `bricks` has the generation of the last update, from scratch
  // otherwise. A plane is identified by its exact normal and offset.
  void update(const BrickSet &bricks, const std::vector<CutPlane> &cuts);

  // The side of brick `i` for the planes of the last update().
  CutPlanes::Side side(uint32_t i) const {
    if (dropped_[i] > 0) return CutPlanes::Side::kDropped;
    return crossed_[i] > 0 ? CutPlanes::Side::kBoth : CutPlanes::Side::kKept;
  }
  bool any_plane() const { return !applied_.empty(); }
  const Update &last_update() const { return last_; }

 private:
  struct Node {  // a run of bricks [first, last) along the z-order curve and its centres' box
    glm::dvec3 lo, hi;
    uint32_t first = 0, last = 0;
    uint32_t left = 0, right = 0;  // children (0: a leaf)
  };
  void build_hierarchy(const BrickSet &bricks);
  uint32_t build_node(const BrickSet &bricks, uint32_t first, uint32_t last);
  // Adds `delta` (+1 or -1) to the counters of the bricks the plane drops or crosses.
  void apply(const BrickSet &bricks, const CutPlanes::Plane &plane, int delta);

  uint64_t generation_ = 0;        // of the bricks the counters describe (0: none yet)
  std::vector<CutPlane> applied_;  // enabled planes counted in, as configured
  std::vector<uint32_t> dropped_;  // per brick: planes that cut it away entirely
  std::vector<uint32_t> crossed_;  // per brick: planes that pass through it
  std::vector<Node> nodes_;        // nodes_[0] is the root when there are bricks
  Update last_;
};

}  // namespace lantern
