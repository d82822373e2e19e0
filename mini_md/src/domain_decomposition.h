// 3-D spatial decomposition: the box is cut into a px*py*pz grid of equal subdomains, one per
// rank, on a Cartesian communicator whose periodicity follows the box.
#pragma once

#include <mpi.h>

#include <array>

#include "box.h"
#include "vec3.h"

namespace mini_md {

class DomainDecomposition {
 public:
  // Chooses the process grid and creates the Cartesian communicator (collective over `comm`).
  // Throws MdError, on every rank, if no grid gives subdomains at least `ghost_cut` wide: the
  // staged ghost exchange reaches only the adjacent subdomain.
  DomainDecomposition(MPI_Comm comm, const Box &box, double ghost_cut);
  ~DomainDecomposition();
  DomainDecomposition(const DomainDecomposition &) = delete;
  DomainDecomposition &operator=(const DomainDecomposition &) = delete;

  MPI_Comm comm() const { return cart_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  const Box &box() const { return box_; }
  const std::array<int, 3> &dims() const { return dims_; }
  const std::array<int, 3> &coords() const { return coords_; }
  const Vec3 &sub_lo() const { return sub_lo_; }
  const Vec3 &sub_hi() const { return sub_hi_; }
  // Rank of the neighbour below (dir 0) or above (dir 1) along `dim`; MPI_PROC_NULL at a wall.
  int neighbor(int dim, int dir) const { return neighbor_[dim][dir]; }
  // Whether this rank touches the lower (dir 0) / upper (dir 1) face of the global box.
  bool at_box_face(int dim, int dir) const {
    return dir == 0 ? coords_[dim] == 0 : coords_[dim] == dims_[dim] - 1;
  }
  // Subdomain boundary `c` of `dim` (0..dims[dim]); both neighbours compute the identical value.
  double boundary(int dim, int c) const;

 private:
  Box box_;
  MPI_Comm cart_ = MPI_COMM_NULL;
  int rank_ = 0;
  int size_ = 1;
  std::array<int, 3> dims_{1, 1, 1};
  std::array<int, 3> coords_{0, 0, 0};
  std::array<std::array<int, 2>, 3> neighbor_{};
  Vec3 sub_lo_{0, 0, 0};
  Vec3 sub_hi_{0, 0, 0};
};

// The process grid for `nranks` ranks: among all factorisations whose subdomains are at least
// `ghost_cut` wide on every axis, the one with the least ghost surface (what MPI_Dims_create
// does for a cube, but aware of the box's aspect ratio). Returns {0,0,0} if none fits.
std::array<int, 3> choose_process_grid(int nranks, const Box &box, double ghost_cut);

}  // namespace mini_md
