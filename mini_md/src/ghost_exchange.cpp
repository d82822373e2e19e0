#include "ghost_exchange.h"

namespace mini_md {

namespace {
constexpr int kTagCount = 101;
constexpr int kTagData = 102;
}  // namespace

GhostExchange::Swap GhostExchange::make_swap(const Atoms &atoms, const DomainDecomposition &dd,
                                             int dim, int dir, double ghost_cut,
                                             int candidates) const {
  Swap swap;
  swap.send_to = dd.neighbor(dim, dir);
  swap.recv_from = dd.neighbor(dim, 1 - dir);
  swap.to_self = swap.send_to == dd.rank() && swap.recv_from == dd.rank();
  // Crossing the periodic seam: the copy appears one box length away on the far side.
  if (dd.box().periodic[dim] && dd.at_box_face(dim, dir)) {
    swap.shift[dim] = dir == 0 ? dd.box().length(dim) : -dd.box().length(dim);
  }
  if (swap.send_to == MPI_PROC_NULL) return swap;
  const double lo_edge = dd.sub_lo()[dim] + ghost_cut;
  const double hi_edge = dd.sub_hi()[dim] - ghost_cut;
  for (int i = 0; i < candidates; ++i) {
    const double c = atoms.x[i][dim];
    if (dir == 0 ? c < lo_edge : c >= hi_edge) swap.send_index.push_back(i);
  }
  return swap;
}

void GhostExchange::receive_ghosts(Atoms &atoms, Swap &swap) {
  const int nsend = static_cast<int>(swap.send_index.size());
  // Position and id travel together; ids fit a double exactly (< 2^53).
  send_buf_.resize(4 * static_cast<size_t>(nsend));
  for (int k = 0; k < nsend; ++k) {
    const int i = swap.send_index[k];
    for (int d = 0; d < 3; ++d) send_buf_[4 * k + d] = atoms.x[i][d] + swap.shift[d];
    send_buf_[4 * k + 3] = static_cast<double>(atoms.id[i]);
  }
  int nrecv = 0;
  if (swap.to_self) {
    nrecv = nsend;
    recv_buf_ = send_buf_;
  } else {
    MPI_Sendrecv(&nsend, 1, MPI_INT, swap.send_to, kTagCount, &nrecv, 1, MPI_INT, swap.recv_from,
                 kTagCount, comm_, MPI_STATUS_IGNORE);
    recv_buf_.resize(4 * static_cast<size_t>(nrecv));
    MPI_Sendrecv(send_buf_.data(), 4 * nsend, MPI_DOUBLE, swap.send_to, kTagData, recv_buf_.data(),
                 4 * nrecv, MPI_DOUBLE, swap.recv_from, kTagData, comm_, MPI_STATUS_IGNORE);
  }
  swap.recv_first = atoms.ntotal();
  swap.recv_count = nrecv;
  atoms.resize_ghosts(atoms.nghost + nrecv);
  for (int k = 0; k < nrecv; ++k) {
    const int g = swap.recv_first + k;
    atoms.x[g] = Vec3{recv_buf_[4 * k], recv_buf_[4 * k + 1], recv_buf_[4 * k + 2]};
    atoms.id[g] = static_cast<int64_t>(recv_buf_[4 * k + 3]);
  }
}

void GhostExchange::borders(Atoms &atoms, const DomainDecomposition &dd, double ghost_cut) {
  comm_ = dd.comm();
  atoms.clear_ghosts();
  swaps_.clear();
  for (int dim = 0; dim < 3; ++dim) {
    // Both directions of one axis draw from the same candidates: owned atoms plus ghosts of the
    // earlier axes, not the ghosts this axis just produced.
    const int candidates = atoms.ntotal();
    for (int dir = 0; dir < 2; ++dir) {
      Swap swap = make_swap(atoms, dd, dim, dir, ghost_cut, candidates);
      if (swap.send_to == MPI_PROC_NULL && swap.recv_from == MPI_PROC_NULL) continue;
      receive_ghosts(atoms, swap);
      swaps_.push_back(std::move(swap));
    }
  }
  ghosts_ = atoms.nghost;
}

void GhostExchange::forward_positions(Atoms &atoms) {
  Vec3 *x = atoms.x.data();
  for (const Swap &swap : swaps_) {
    const int nsend = static_cast<int>(swap.send_index.size());
    if (swap.to_self) {
      for (int k = 0; k < nsend; ++k) {
        const Vec3 &s = x[swap.send_index[k]];
        x[swap.recv_first + k] =
            Vec3{s[0] + swap.shift[0], s[1] + swap.shift[1], s[2] + swap.shift[2]};
      }
      continue;
    }
    send_buf_.resize(3 * static_cast<size_t>(nsend));
    for (int k = 0; k < nsend; ++k) {
      const Vec3 &s = x[swap.send_index[k]];
      for (int d = 0; d < 3; ++d) send_buf_[3 * k + d] = s[d] + swap.shift[d];
    }
    // Ghosts of one swap are contiguous, so they are received straight into x.
    MPI_Sendrecv(send_buf_.data(), 3 * nsend, MPI_DOUBLE, swap.send_to, kTagData,
                 reinterpret_cast<double *>(x + swap.recv_first), 3 * swap.recv_count, MPI_DOUBLE,
                 swap.recv_from, kTagData, comm_, MPI_STATUS_IGNORE);
  }
}

void GhostExchange::reverse_forces(Atoms &atoms) {
  Vec3 *f = atoms.f.data();
  for (auto it = swaps_.rbegin(); it != swaps_.rend(); ++it) {
    const Swap &swap = *it;
    const int nsend = static_cast<int>(swap.send_index.size());
    if (swap.to_self) {
      for (int k = 0; k < nsend; ++k) {
        Vec3 &t = f[swap.send_index[k]];
        const Vec3 &g = f[swap.recv_first + k];
        t[0] += g[0];
        t[1] += g[1];
        t[2] += g[2];
      }
      continue;
    }
    recv_buf_.resize(3 * static_cast<size_t>(nsend));
    MPI_Sendrecv(reinterpret_cast<double *>(f + swap.recv_first), 3 * swap.recv_count, MPI_DOUBLE,
                 swap.recv_from, kTagData, recv_buf_.data(), 3 * nsend, MPI_DOUBLE, swap.send_to,
                 kTagData, comm_, MPI_STATUS_IGNORE);
    for (int k = 0; k < nsend; ++k) {
      Vec3 &t = f[swap.send_index[k]];
      for (int d = 0; d < 3; ++d) t[d] += recv_buf_[3 * k + d];
    }
  }
}

}  // namespace mini_md
