// Ghost atoms: copies of atoms within the ghost cutoff of this subdomain's faces, owned by a
// neighbouring rank or (periodic axis with one rank) by this rank as a shifted image.
//
// Six staged swaps, LAMMPS style: along x send down, send up; then y; then z. A swap also
// forwards ghosts received along earlier axes, so edge and corner ghosts arrive in two or three
// hops without diagonal messages. The swap lists are built on rebuild steps (borders) and reused
// every step to forward positions; forces accumulated on ghosts (Newton's third law across ranks)
// travel the same swaps in reverse and are added to their owners.
#pragma once

#include <mpi.h>

#include <vector>

#include "atoms.h"
#include "domain_decomposition.h"

namespace mini_md {

class GhostExchange {
 public:
  // Drops the old ghosts and creates new ones for the current owned positions.
  void borders(Atoms &atoms, const DomainDecomposition &dd, double ghost_cut);
  // Copies owners' current positions into the ghosts (every step between rebuilds).
  void forward_positions(Atoms &atoms);
  // Adds the forces accumulated on ghosts to the atoms they copy.
  void reverse_forces(Atoms &atoms);
  int64_t ghost_count() const { return ghosts_; }

 private:
  struct Swap {
    int send_to = MPI_PROC_NULL;
    int recv_from = MPI_PROC_NULL;
    bool to_self = false;  // periodic axis with one rank: a local copy, no message
    Vec3 shift{0, 0, 0};   // periodic image shift applied to sent positions
    std::vector<int> send_index;
    int recv_first = 0;
    int recv_count = 0;
  };
  Swap make_swap(const Atoms &atoms, const DomainDecomposition &dd, int dim, int dir,
                 double ghost_cut, int candidates) const;
  void receive_ghosts(Atoms &atoms, Swap &swap);

  MPI_Comm comm_ = MPI_COMM_NULL;
  std::vector<Swap> swaps_;
  std::vector<double> send_buf_;
  std::vector<double> recv_buf_;
  int64_t ghosts_ = 0;
};

}  // namespace mini_md
