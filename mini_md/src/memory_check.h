// Refuses a run whose atoms cannot fit in memory, before any atom is made: `--cells 2000` asks
// for 3.2e10 atoms, and the kernel's out-of-memory killer would end the run (or another process)
// without a word.
#pragma once

#include <mpi.h>

#include <cstdint>

#include "run_config.h"

namespace mini_md {

// Bytes per atom of a run, measured: the resident size of `mini_md --cells 40` and `--cells 60`
// (256,000 and 864,000 atoms, 1 rank, /usr/bin/time -v) differs by 345 MB, 567 bytes per atom
// (positions, velocities, forces, ids, types, build positions, ghosts, the neighbour list, bins);
// rounded up.
inline constexpr int64_t kBytesPerAtom = 600;

// The most atoms the scene can hold at cfg.cells (before voids are cut or the drop is carved):
// 4 N^3 for lattice, random and droplet, 4 N^3 + the flyer's 4 N^2 max(2, N/4) for void_impact.
int64_t atoms_upper_bound(const RunConfig &cfg);

// Collective. Throws MdError (on every rank alike) when atoms_upper_bound * kBytesPerAtom, split
// evenly over the ranks of comm, exceeds the memory of a node (sysconf's physical pages) shared
// by the ranks of comm on it; the message gives the figures and the largest --cells that fits.
void check_memory(const RunConfig &cfg, MPI_Comm comm);

}  // namespace mini_md
