// lantern-bench --scale 10,38,100: whole frames of tens to hundreds of millions of particles
// through the pipeline (Runtime on MPI_COMM_WORLD, every key at its default), under mpiexec.
//
// For each scene (fcc crystal, and the crystal beside a sparse gas) and each size (millions of
// particles over all ranks), every rank generates only its own share (a slab of the crystal, its
// share of the gas), publishes it and renders: the first frame (bricks built), then `runs` later
// frames with the positions moved a little before each (bricks refit). Next to every frame, in
// the same run, each rank times one streaming pass over its positions: the reference the
// per-particle costs are quoted against. Memory is the process's own: the high-water mark (reset
// once the scene is generated) and the resident size after the frames, each minus the resident
// size just before the first frame (the published arrays and the libraries), per local particle.
#pragma once

#include <string>
#include <vector>

namespace lantern::bench {

struct ScaleOptions {
  std::vector<double> millions;                             // particles over all ranks
  std::vector<std::string> scenes{"fcc", "heterogeneous"};  // --scale-scenes
  int runs = 5;                                             // later frames per size
  int size = 1024;                                          // image width and height
  std::string out = ".";                                    // images and stats go here
};

// Prints one table per scene (rank 0) and writes DIR/scale_bench.csv. False if a frame failed or a
// file could not be written.
bool run_scale_bench(const ScaleOptions &options);

}  // namespace lantern::bench
