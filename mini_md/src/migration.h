// Migration: on rebuild steps, owned atoms that left this rank's subdomain are handed to the rank
// that now owns them, and the global atom count is verified.
#pragma once

#include <mpi.h>

#include <cstdint>

#include "atoms.h"
#include "domain_decomposition.h"

namespace mini_md {

struct MigrationStats {
  int64_t moved = 0;  // atoms this rank sent away
  int max_hops = 0;   // most hops any atom needed along one axis (> 1: crossed several subdomains)
};

// Wraps periodic coordinates into the box, then, axis by axis, passes atoms outside this rank's
// slab to the neighbour on that side, repeating until every rank holds only its own atoms. An
// atom that crossed several subdomains between rebuilds therefore travels several hops; none is
// dropped. Collective; requires that no ghosts exist. Throws MdError on a non-finite coordinate.
MigrationStats migrate_atoms(Atoms &atoms, const DomainDecomposition &dd, int64_t step);

// Throws MdError on every rank if the owned atoms no longer add up to `expected`.
void check_atom_count(const Atoms &atoms, MPI_Comm comm, int64_t expected, int64_t step);

}  // namespace mini_md
