// Test support: bonded systems for the bond tests and benchmarks, reproducible from their
// parameters - a polymer melt of random-walk chains and a cross-linked network - as plain
// vectors (positions, types, ids and bond pairs by index).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "tests/support/hash_noise.h"

namespace lantern::testing {

struct BondedSystem {
  std::vector<double> xyz;     // x, y, z per atom
  std::vector<int32_t> type;   // one per atom
  std::vector<int64_t> id;     // global ids (1-based, as LAMMPS numbers atoms)
  std::vector<int64_t> bonds;  // first, second per bond: atom indices
  std::vector<int32_t> bond_type;
  double box = 0.0;  // edge of the cubic box [0, box)^3 (periodic), 0 when there is none
  size_t atoms() const { return type.size(); }
  size_t bond_count() const { return bond_type.size(); }
};

// `chains` freely rotating chains of `beads` beads (bond length `bond`, bond angle >= 60
// degrees, so a chain never folds back onto its previous bead), started uniformly in a periodic
// cube of edge `box` and wrapped into it, as an MD code stores them: bonds of chains that cross a
// face join atoms on opposite sides of the box. Types: 0 along the chain, 1 at its ends; bond
// types 0 and 1 alternating.
inline BondedSystem polymer_melt(int chains, int beads, double box, double bond = 0.97,
                                 uint32_t seed = 1) {
  BondedSystem s;
  s.box = box;
  const auto wrap = [box](double v) { return v - box * std::floor(v / box); };
  uint32_t h = hash(seed * 2654435761U + 7U);
  const auto next = [&h]() { return unit(h = hash(h + 0x9e3779b9U)); };
  for (int c = 0; c < chains; ++c) {
    double p[3] = {box * next(), box * next(), box * next()}, dir[3] = {1, 0, 0};
    for (int b = 0; b < beads; ++b) {
      if (b > 0) {
        double step[3];
        do {  // a random unit step at most 120 degrees from the last one
          const double z = 2.0 * next() - 1.0, phi = 6.283185307179586 * next();
          const double r = std::sqrt(1.0 - z * z);
          step[0] = r * std::cos(phi), step[1] = r * std::sin(phi), step[2] = z;
        } while (step[0] * dir[0] + step[1] * dir[1] + step[2] * dir[2] < -0.5);
        for (int k = 0; k < 3; ++k) p[k] += bond * step[k], dir[k] = step[k];
        const int64_t i = int64_t(s.atoms());
        s.bonds.insert(s.bonds.end(), {i - 1, i});
        s.bond_type.push_back(int32_t(b % 2));
      }
      for (int k = 0; k < 3; ++k) s.xyz.push_back(wrap(p[k]));
      s.type.push_back(b == 0 || b == beads - 1 ? 1 : 0);
      s.id.push_back(int64_t(s.atoms()));
    }
  }
  return s;
}

// A cross-linked network: cross-link atoms (type 1) on a cubic lattice of n^3 sites, spacing
// `cell`, each joined to its +x, +y and +z neighbours by a strand of `strand` beads (type 0) in a
// straight line jittered by `jitter`; not periodic (an open block). Bond type 0 in strands, 1
// where a strand meets a cross-link.
inline BondedSystem network(int n, int strand, double cell, double jitter = 0.15,
                            uint32_t seed = 3) {
  BondedSystem s;
  uint32_t h = hash(seed * 2246822519U + 11U);
  const auto next = [&h]() { return unit(h = hash(h + 0x9e3779b9U)) - 0.5; };
  const auto add_atom = [&](double x, double y, double z, int32_t type) {
    s.xyz.insert(s.xyz.end(), {x + jitter * next(), y + jitter * next(), z + jitter * next()});
    s.type.push_back(type);
    s.id.push_back(int64_t(s.atoms()));
    return int64_t(s.atoms() - 1);
  };
  const auto site = [n](int i, int j, int k) { return (int64_t(k) * n + j) * n + i; };
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) add_atom(i * cell, j * cell, k * cell, 1);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int axis = 0; axis < 3; ++axis) {
          const int to[3] = {i + (axis == 0), j + (axis == 1), k + (axis == 2)};
          if (to[0] >= n || to[1] >= n || to[2] >= n) continue;
          int64_t previous = site(i, j, k);
          for (int b = 1; b <= strand; ++b) {
            const double f = double(b) / (strand + 1);
            const int64_t bead =
                add_atom((i + f * (to[0] - i)) * cell, (j + f * (to[1] - j)) * cell,
                         (k + f * (to[2] - k)) * cell, 0);
            s.bonds.insert(s.bonds.end(), {previous, bead});
            s.bond_type.push_back(b == 1 ? 1 : 0);
            previous = bead;
          }
          s.bonds.insert(s.bonds.end(), {previous, site(to[0], to[1], to[2])});
          s.bond_type.push_back(1);
        }
  return s;
}

}  // namespace lantern::testing
