// Cutting planes (a scene's cut_planes): a particle whose CENTRE has dot(n, x) > offset is dropped.
// Bricks wholly on the dropped side are skipped; bricks wholly on the kept side need no
// per-particle test. Planes with `enabled: false` are left out. World space, double precision.
// Thread-safety: immutable value type.
#pragma once

#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/config/config.h"

namespace lantern {

class CutPlanes {
 public:
  explicit CutPlanes(const std::vector<CutPlane> &cuts) {
    for (const CutPlane &c : cuts)
      if (c.enabled) planes_.push_back(plane_of(c));
  }
  bool empty() const { return planes_.empty(); }
  // The same enabled planes, in the same order, bit for bit: the same particles dropped.
  bool same_as(const CutPlanes &other) const {
    if (planes_.size() != other.planes_.size()) return false;
    for (size_t i = 0; i < planes_.size(); ++i) {
      const Plane &a = planes_[i], &b = other.planes_[i];
      if (a.n != b.n || a.offset != b.offset) return false;
    }
    return true;
  }

  bool drops(const glm::dvec3 &p) const {
    for (const Plane &pl : planes_)
      if (glm::dot(pl.n, p) > pl.offset) return true;
    return false;
  }

  enum class Side { kDropped, kKept, kBoth };
  struct Plane {
    glm::dvec3 n;
    double offset;
  };
  static Plane plane_of(const CutPlane &c) {
    return {{c.normal[0], c.normal[1], c.normal[2]}, c.offset};
  }

  // One plane against the centres' box [lo, hi]. The one computation of a brick's side: the
  // incremental counts (brick_cut_counts.h) use it too, so both agree bit for bit. Monotone in
  // the box: a box inside [lo, hi] is dropped (kept) whenever [lo, hi] is.
  static Side classify_box(const Plane &pl, const glm::dvec3 &lo, const glm::dvec3 &hi) {
    // Extremes of a linear function over a box: pick each coordinate by the normal's sign.
    const glm::dvec3 near_pt{pl.n.x >= 0 ? lo.x : hi.x, pl.n.y >= 0 ? lo.y : hi.y,
                             pl.n.z >= 0 ? lo.z : hi.z};
    const glm::dvec3 far_pt = lo + hi - near_pt;
    if (glm::dot(pl.n, near_pt) > pl.offset) return Side::kDropped;
    return glm::dot(pl.n, far_pt) > pl.offset ? Side::kBoth : Side::kKept;
  }

  // Every plane against the centres' box [lo, hi]: dropped if any plane drops it all, else
  // kBoth if any plane passes through it.
  Side classify_box(const glm::dvec3 &lo, const glm::dvec3 &hi) const {
    bool all_kept = true;
    for (const Plane &pl : planes_) {
      const Side side = classify_box(pl, lo, hi);
      if (side == Side::kDropped) return Side::kDropped;
      if (side == Side::kBoth) all_kept = false;
    }
    return all_kept ? Side::kKept : Side::kBoth;
  }

 private:
  std::vector<Plane> planes_;
};

}  // namespace lantern
