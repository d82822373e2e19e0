// Cutting planes (SceneConfig::cuts): a particle whose CENTRE has dot(n, x) > offset is dropped.
// Bricks wholly on the dropped side are skipped; bricks wholly on the kept side need no
// per-particle test. World space, double precision. Thread-safety: immutable value type.
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
      planes_.push_back({{c.normal[0], c.normal[1], c.normal[2]}, c.offset});
  }
  bool empty() const { return planes_.empty(); }

  bool drops(const glm::dvec3 &p) const {
    for (const Plane &pl : planes_)
      if (glm::dot(pl.n, p) > pl.offset) return true;
    return false;
  }

  enum class Side { kDropped, kKept, kBoth };
  // The centres' box [lo, hi].
  Side classify_box(const glm::dvec3 &lo, const glm::dvec3 &hi) const {
    bool all_kept = true;
    for (const Plane &pl : planes_) {
      // Extremes of a linear function over a box: pick each coordinate by the normal's sign.
      const glm::dvec3 near_pt{pl.n.x >= 0 ? lo.x : hi.x, pl.n.y >= 0 ? lo.y : hi.y,
                               pl.n.z >= 0 ? lo.z : hi.z};
      const glm::dvec3 far_pt = lo + hi - near_pt;
      if (glm::dot(pl.n, near_pt) > pl.offset) return Side::kDropped;
      if (glm::dot(pl.n, far_pt) > pl.offset) all_kept = false;
    }
    return all_kept ? Side::kKept : Side::kBoth;
  }

 private:
  struct Plane {
    glm::dvec3 n;
    double offset;
  };
  std::vector<Plane> planes_;
};

}  // namespace lantern
