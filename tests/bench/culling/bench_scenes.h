// The scenes lantern-bench renders: generated fcc crystals (seen from outside and from inside)
// and, when mini_md is built, its void_impact and droplet start configurations.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/particles/particle_arrays.h"

namespace lantern::bench {

struct BenchScene {
  std::string name;
  std::string note;         // one line: what it is
  std::vector<double> xyz;  // interleaved positions, owned here (the "simulation's" arrays)
  std::vector<int32_t> type;
  SceneConfig config;  // size, radius, camera, colors, cuts

  ParticleArrays arrays() const;
};

// fcc crystal of 4 n^3 atoms at nearest-neighbour distance 2^(1/6) (the LJ minimum), radius 0.5,
// in lattice order (as a simulation that sorts its atoms spatially would publish them).
BenchScene fcc_outside(int n, int size);
// The same crystal seen by a wide-angle camera inside it.
BenchScene fcc_inside(int n, int size);
// mini_md's scenes at `cells` (false if mini_md is not built; *why says so).
bool mini_md_scene(const std::string &kind, int cells, int size, BenchScene *out, std::string *why);

}  // namespace lantern::bench
