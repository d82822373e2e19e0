// The simulation box as bonds need it: which axes are periodic and how long they are, for the
// minimum-image convention. Set from lantern_set_box() by the pipeline (the dump stage keeps its
// own copy for H5MD's `box`).
//
// Plain value type. Units: the simulation's length unit.
#pragma once

#include <array>
#include <cmath>
#include <limits>

#include <glm/vec3.hpp>

namespace lantern {

struct PeriodicBox {
  std::array<double, 3> length{0, 0, 0};  // high - low per axis
  std::array<bool, 3> periodic{false, false, false};

  // The minimum image of the separation d: along each periodic axis of positive length, d minus
  // the multiple of the length that brings it into [-length / 2, length / 2]. Other axes as given.
  //
  // Nearly every bond is shorter than half the box: there the multiple, nearbyint(d / length), is
  // a zero of d's sign (|d / length| <= 1/2 rounds to 0, a tie to even included), and d minus
  // length times it is d + 0.0 (-0 becomes +0, anything else stays), so that case skips the
  // division and the rounding - a call into libm without SSE4.1 - and gives the same bits.
  // 2 |d| is exact (an overflow is inf, which takes the general path), and a length of inf (a
  // box of finite ends can overflow high - low) takes it too: there the general path gives NaN.
  glm::dvec3 minimum_image(glm::dvec3 d) const {
    constexpr double kMaxLength = std::numeric_limits<double>::max();
    for (int a = 0; a < 3; ++a)
      if (periodic[a] && length[a] > 0.0) {
        if (2.0 * std::abs(d[a]) <= length[a] && length[a] <= kMaxLength)
          d[a] += 0.0;
        else
          d[a] -= length[a] * std::nearbyint(d[a] / length[a]);
      }
    return d;
  }
};

// Where the half-bond of the atom at `atom` ends when its partner is at `partner`: half-way along
// the minimum-image separation (no box: half-way to the partner). Every stage computes a half's
// far end with this one function, so culling bounds and the drawn cylinder agree to the bit.
inline glm::dvec3 half_bond_end(const glm::dvec3 &atom, const glm::dvec3 &partner,
                                const PeriodicBox *box) {
  const glm::dvec3 d = box ? box->minimum_image(partner - atom) : partner - atom;
  return atom + 0.5 * d;
}

}  // namespace lantern
