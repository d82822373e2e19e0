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
  std::vector<double> radius;  // per-particle radii (config.per_particle_radius); empty: none
  SceneConfig config;          // size, radius, camera, colors, cuts

  ParticleArrays arrays() const;
};

// fcc crystal of 4 n^3 atoms at nearest-neighbour distance 2^(1/6) (the LJ minimum), radius 0.5,
// in lattice order (as a simulation that sorts its atoms spatially would publish them).
BenchScene fcc_outside(int n, int size);
// Keeps this rank's block of the particles in their order: of a lattice in lattice order, a
// spatial decomposition, roughly.
void keep_rank_block(BenchScene *s, int rank, int ranks);
// The scene's size, radius, camera, colour by type and cutting planes as the YAML keys of an item
// of `scenes:` (each line indented by four spaces), for benches that run the pipeline.
std::string scene_yaml_keys(const BenchScene &s);
// The same crystal seen by a wide-angle camera inside it.
BenchScene fcc_inside(int n, int size);
// A thin film: fcc of n x n x 2 cells (four atomic layers) seen from outside as fcc_outside,
// where a layer hides those below it only in part (a scene where occlusion culls little).
BenchScene thin_film(int n, int size);
// A dense fcc crystal of n^3 cells beside a sparse gas (the heterogeneous data of Ibrahim et al.
// 2022, Fig. 2).
BenchScene heterogeneous(int n, int size);
// A cosmology-like clustered cloud: `n` particles, 80 % in eight dense Gaussian blobs of
// different sizes and 20 % uniform in a cube of side 200, radius 0.5, typed by blob (fixed seed).
BenchScene clustered_cloud(int64_t n, int size);
// mini_md's scenes at `cells` (false if mini_md is not built; *why says so).
bool mini_md_scene(const std::string &kind, int cells, int size, BenchScene *out, std::string *why);

// Gives every particle of `s` its own radius, a multiple of the scene's radius r (fixed seed):
// "uniform": uniform in [0.3, 1.2] r; "bimodal": half 0.5 r, half 1.2 r, mixed at random. False
// (and `s` unchanged) for any other name.
bool assign_radii(const std::string &mix, BenchScene *s);

}  // namespace lantern::bench
