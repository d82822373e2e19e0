// The simulation box as bonds need it: which axes are periodic, how long they are and, for a
// triclinic box, its tilt, for the minimum-image convention. Set from lantern_set_box() or
// lantern_set_triclinic_box() by the pipeline (the dump stage keeps its own copy for H5MD's `box`).
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
  // LAMMPS's restricted triclinic box: edge vectors a = (lx, 0, 0), b = (xy, ly, 0) and
  // c = (xz, yz, lz), tilt = {xy, xz, yz}. All zero: the orthogonal box (and its exact bits).
  std::array<double, 3> tilt{0, 0, 0};

  bool tilted() const { return tilt[0] != 0.0 || tilt[1] != 0.0 || tilt[2] != 0.0; }

  // The minimum image of the separation d: along each periodic axis of positive length, d minus
  // the multiple of the length that brings it into [-length / 2, length / 2]. Other axes as given.
  //
  // Nearly every bond is shorter than half the box: there the multiple, nearbyint(d / length), is
  // a zero of d's sign (|d / length| <= 1/2 rounds to 0, a tie to even included), and d minus
  // length times it is d + 0.0 (-0 becomes +0, anything else stays), so that case skips the
  // division and the rounding - a call into libm without SSE4.1 - and gives the same bits.
  // 2 |d| is exact (an overflow is inf, which takes the general path), and a length of inf (a
  // box of finite ends can overflow high - low) takes it too: there the general path gives NaN.
  //
  // A triclinic box wraps as LAMMPS's Domain::minimum_image does: along c first (which moves x and
  // y by the tilts xz and yz), then b (x by xy), then a. Where every axis is within half its
  // length nothing moves, the same d + 0.0 as the orthogonal shortcut (which brick_bonds relies
  // on); the image is the closest one for bonds shorter than half the box's heights.
  glm::dvec3 minimum_image(glm::dvec3 d) const {
    constexpr double kMaxLength = std::numeric_limits<double>::max();
    if (tilted()) return tilted_minimum_image(d);
    for (int a = 0; a < 3; ++a)
      if (periodic[a] && length[a] > 0.0) {
        if (2.0 * std::abs(d[a]) <= length[a] && length[a] <= kMaxLength)
          d[a] += 0.0;
        else
          d[a] -= length[a] * std::nearbyint(d[a] / length[a]);
      }
    return d;
  }

 private:
  glm::dvec3 tilted_minimum_image(glm::dvec3 d) const {
    constexpr double kMaxLength = std::numeric_limits<double>::max();
    for (int a = 2; a >= 0; --a) {
      if (!periodic[a] || !(length[a] > 0.0)) continue;
      if (2.0 * std::abs(d[a]) <= length[a] && length[a] <= kMaxLength) {
        d[a] += 0.0;
        continue;
      }
      const double k = std::nearbyint(d[a] / length[a]);
      d[a] -= length[a] * k;
      if (a == 2) d.x -= tilt[1] * k, d.y -= tilt[2] * k;  // c = (xz, yz, lz)
      if (a == 1) d.x -= tilt[0] * k;                      // b = (xy, ly, 0)
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
