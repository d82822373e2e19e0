// lantern-bench --bond-scenes melt,network: bonded scenes (atoms and half-bonds, drawn by the CPU
// raster through the pipeline's rank drawing) in each culling mode against brute force (every
// atom and half-bond drawn, no culling at all): ms per frame, atoms and half-bonds culled, and
// the image error. Scenes: `melt`, a polymer melt of 100-bead random-walk chains (bond 0.97) at
// number density 0.85 in a periodic cube, atoms of radius 0.3, bonds 0.15; `network`, the simple-
// cubic network of tests/bench/lammps_dump_image_bonds.sh (spacing 1, every nearest pair bonded,
// periodic), atoms 0.25, bonds 0.15. --bond-atoms N sets the atom count of both (default 1 M).
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

namespace lantern::bench {

// The CSV header of bond_bench.csv.
const char *bond_csv_header();

// Runs every mode on scene `name` (melt or network) of about `atoms` atoms at size x size,
// `runs` times (median, modes interleaved run by run); prints a table, appends CSV rows, and sets
// *exact to false when an exact mode's image differs from brute force. False for an unknown
// scene name.
bool run_bond_bench(const std::string &name, int64_t atoms, int size, int runs, std::ostream &csv,
                    bool *exact);

}  // namespace lantern::bench
