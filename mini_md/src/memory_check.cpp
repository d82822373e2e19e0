#include "memory_check.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "md_error.h"

namespace mini_md {
namespace {

std::string gib(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GiB", bytes / double(int64_t(1) << 30));
  return text;
}

}  // namespace

int64_t atoms_upper_bound(const RunConfig &cfg) {
  const int64_t n = cfg.cells;
  const int64_t lattice = 4 * n * n * n;
  if (cfg.scene != SceneKind::kVoidImpact || cfg.random_start) return lattice;
  return lattice + 4 * n * n * std::max<int64_t>(2, n / 4);
}

void check_memory(const RunConfig &cfg, MPI_Comm comm) {
  int ranks = 1, node_ranks = 1;
  MPI_Comm_size(comm, &ranks);
  MPI_Comm node = MPI_COMM_NULL;
  if (MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node) == MPI_SUCCESS) {
    MPI_Comm_size(node, &node_ranks);
    MPI_Comm_free(&node);
  }
  // The smallest node decides for all: every rank throws alike.
  double node_bytes = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGESIZE));
  double per_rank = node_bytes / node_ranks;
  MPI_Allreduce(MPI_IN_PLACE, &per_rank, 1, MPI_DOUBLE, MPI_MIN, comm);
  const int64_t atoms = atoms_upper_bound(cfg);
  const double needed = double(atoms) * double(kBytesPerAtom) / ranks;
  if (needed <= per_rank) return;
  // The largest --cells whose atoms fit, from the scene's atoms per cell^3.
  const double per_cell3 = double(atoms) / std::pow(double(cfg.cells), 3.0);
  const int fits =
      int(std::floor(std::cbrt(per_rank * ranks / (per_cell3 * double(kBytesPerAtom)))));
  char count[32];
  std::snprintf(count, sizeof count, "%.3g", double(atoms));
  throw MdError("--cells " + std::to_string(cfg.cells) + ": up to " + count + " atoms, about " +
                gib(needed) + " per rank on " + std::to_string(ranks) + " rank" +
                (ranks == 1 ? "" : "s") + " (" + std::to_string(kBytesPerAtom) +
                " bytes per atom), more than the " + gib(per_rank) +
                " a rank has here (a node's memory shared by " + std::to_string(node_ranks) +
                " rank" + (node_ranks == 1 ? "" : "s") + "); use --cells " +
                std::to_string(std::max(1, fits)) + " or fewer, or more nodes");
}

}  // namespace mini_md
