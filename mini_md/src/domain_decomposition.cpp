#include "domain_decomposition.h"

#include <limits>
#include <sstream>

#include "md_error.h"

namespace mini_md {

std::array<int, 3> choose_process_grid(int nranks, const Box &box, double ghost_cut) {
  std::array<int, 3> best{0, 0, 0};
  double best_surface = std::numeric_limits<double>::infinity();
  for (int px = 1; px <= nranks; ++px) {
    if (nranks % px != 0) continue;
    for (int py = 1; py <= nranks / px; ++py) {
      if ((nranks / px) % py != 0) continue;
      const int pz = nranks / px / py;
      const double lx = box.length(0) / px, ly = box.length(1) / py, lz = box.length(2) / pz;
      if (lx < ghost_cut || ly < ghost_cut || lz < ghost_cut) continue;
      // Ghost volume per rank is proportional to the subdomain's surface.
      const double surface = lx * ly + ly * lz + lx * lz;
      if (surface < best_surface * (1 - 1e-12)) {
        best_surface = surface;
        best = {px, py, pz};
      }
    }
  }
  return best;
}

DomainDecomposition::DomainDecomposition(MPI_Comm comm, const Box &box, double ghost_cut)
    : box_(box) {
  MPI_Comm_size(comm, &size_);
  dims_ = choose_process_grid(size_, box, ghost_cut);
  if (dims_[0] == 0) {
    std::ostringstream msg;
    msg << "cannot decompose a " << box.length(0) << " x " << box.length(1) << " x "
        << box.length(2) << " box over " << size_
        << " ranks: every subdomain must be at least cutoff + skin = " << ghost_cut
        << " wide on each axis (the ghost exchange reaches only adjacent subdomains). Use fewer"
        << " ranks or a larger --cells.";
    throw MdError(msg.str());
  }
  // MPI_Dims_create validates the grid against MPI's own constraints (all entries preset).
  int dims[3] = {dims_[0], dims_[1], dims_[2]};
  MPI_Dims_create(size_, 3, dims);
  const int periods[3] = {box.periodic[0], box.periodic[1], box.periodic[2]};
  MPI_Cart_create(comm, 3, dims, periods, /*reorder=*/0, &cart_);
  MPI_Comm_rank(cart_, &rank_);
  int coords[3];
  MPI_Cart_coords(cart_, rank_, 3, coords);
  for (int d = 0; d < 3; ++d) {
    coords_[d] = coords[d];
    MPI_Cart_shift(cart_, d, 1, &neighbor_[d][0], &neighbor_[d][1]);
    sub_lo_[d] = boundary(d, coords_[d]);
    sub_hi_[d] = boundary(d, coords_[d] + 1);
  }
}

DomainDecomposition::~DomainDecomposition() {
  if (cart_ != MPI_COMM_NULL) MPI_Comm_free(&cart_);
}

double DomainDecomposition::boundary(int dim, int c) const {
  if (c == dims_[dim]) return box_.hi[dim];
  return box_.lo[dim] + box_.length(dim) * c / dims_[dim];
}

}  // namespace mini_md
