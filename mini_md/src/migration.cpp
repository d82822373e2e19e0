#include "migration.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "md_error.h"

namespace mini_md {

namespace {

constexpr int kDoublesPerAtom = 8;  // x[3], v[3], id, type
constexpr int kTagCount = 201;
constexpr int kTagData = 202;

// Wraps periodic coordinates; returns the smallest id with a non-finite coordinate, or -1.
int64_t wrap_periodic(Atoms &atoms, const Box &box) {
  int64_t bad = -1;
  for (int i = 0; i < atoms.nlocal; ++i) {
    for (int d = 0; d < 3; ++d) {
      double &c = atoms.x[i][d];
      if (!std::isfinite(c)) {
        if (bad < 0 || atoms.id[i] < bad) bad = atoms.id[i];
        continue;
      }
      if (!box.periodic[d] || (c >= box.lo[d] && c < box.hi[d])) continue;
      const double len = box.length(d);
      c -= len * std::floor((c - box.lo[d]) / len);
      // Round-off can land exactly on hi (hi belongs to the next image), and for absurd
      // coordinates (a run-away atom) the reduction itself is inexact: clamp into the box.
      if (c >= box.hi[d]) c -= len;
      if (c < box.lo[d] || c >= box.hi[d]) c = box.lo[d];
    }
  }
  return bad;
}

// Collective: every rank throws if any rank saw a non-finite coordinate.
void stop_on_nonfinite(int64_t local_bad, MPI_Comm comm, int64_t step) {
  int64_t bad = local_bad < 0 ? INT64_MAX : local_bad;
  MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_INT64_T, MPI_MIN, comm);
  if (bad == INT64_MAX) return;
  std::ostringstream msg;
  msg << "step " << step << ": atom " << bad
      << " has a non-finite position; the integration is unstable. Use a smaller --dt or start"
      << " with --relax.";
  throw MdError(msg.str());
}

// Which way atom coordinate c must move along `dim`: -1 down, +1 up, 0 stays. At a wall there
// is no neighbour: atoms on the wall (reflected exactly onto it) stay with the boundary rank.
int direction(double c, int dim, const DomainDecomposition &dd) {
  if (c < dd.sub_lo()[dim] && dd.neighbor(dim, 0) != MPI_PROC_NULL) return -1;
  if (c >= dd.sub_hi()[dim] && dd.neighbor(dim, 1) != MPI_PROC_NULL) return +1;
  return 0;
}

void pack(const Atoms &atoms, int i, std::vector<double> &buf) {
  const Vec3 &x = atoms.x[i];
  const Vec3 &v = atoms.v[i];
  buf.insert(buf.end(), {x[0], x[1], x[2], v[0], v[1], v[2], static_cast<double>(atoms.id[i]),
                         static_cast<double>(atoms.type[i])});
}

void unpack(Atoms &atoms, const std::vector<double> &buf) {
  for (size_t k = 0; k < buf.size(); k += kDoublesPerAtom) {
    const double *a = &buf[k];
    atoms.add_owned(Vec3{a[0], a[1], a[2]}, Vec3{a[3], a[4], a[5]}, static_cast<int64_t>(a[6]),
                    static_cast<int32_t>(a[7]));
  }
}

// Moves leaving atoms into the two send buffers and compacts the rest in place (order kept).
void extract_leavers(Atoms &atoms, int dim, const DomainDecomposition &dd,
                     std::vector<double> &down, std::vector<double> &up) {
  down.clear();
  up.clear();
  int keep = 0;
  for (int i = 0; i < atoms.nlocal; ++i) {
    const int dir = direction(atoms.x[i][dim], dim, dd);
    if (dir < 0) {
      pack(atoms, i, down);
    } else if (dir > 0) {
      pack(atoms, i, up);
    } else {
      if (keep != i) {
        atoms.x[keep] = atoms.x[i];
        atoms.v[keep] = atoms.v[i];
        atoms.f[keep] = atoms.f[i];
        atoms.id[keep] = atoms.id[i];
        atoms.type[keep] = atoms.type[i];
        atoms.scalar[keep] = atoms.scalar[i];
        atoms.x_build[keep] = atoms.x_build[i];
      }
      ++keep;
    }
  }
  atoms.nlocal = keep;
  atoms.x.resize(keep);
  atoms.v.resize(keep);
  atoms.f.resize(keep);
  atoms.id.resize(keep);
  atoms.type.resize(keep);
  atoms.scalar.resize(keep);
  atoms.x_build.resize(keep);
}

std::vector<double> exchange(const std::vector<double> &send, int to, int from, MPI_Comm comm) {
  int nsend = static_cast<int>(send.size());
  int nrecv = 0;
  MPI_Sendrecv(&nsend, 1, MPI_INT, to, kTagCount, &nrecv, 1, MPI_INT, from, kTagCount, comm,
               MPI_STATUS_IGNORE);
  std::vector<double> recv(nrecv);
  MPI_Sendrecv(send.data(), nsend, MPI_DOUBLE, to, kTagData, recv.data(), nrecv, MPI_DOUBLE, from,
               kTagData, comm, MPI_STATUS_IGNORE);
  return recv;
}

}  // namespace

MigrationStats migrate_atoms(Atoms &atoms, const DomainDecomposition &dd, int64_t step) {
  stop_on_nonfinite(wrap_periodic(atoms, dd.box()), dd.comm(), step);
  MigrationStats stats;
  std::vector<double> down, up;
  for (int dim = 0; dim < 3; ++dim) {
    if (dd.dims()[dim] == 1) continue;  // wrapping alone placed them
    // One hop per pass; dims[dim] passes reach any slab, so more means something is wrong.
    for (int hop = 1;; ++hop) {
      extract_leavers(atoms, dim, dd, down, up);
      stats.moved += static_cast<int64_t>((down.size() + up.size()) / kDoublesPerAtom);
      unpack(atoms, exchange(down, dd.neighbor(dim, 0), dd.neighbor(dim, 1), dd.comm()));
      unpack(atoms, exchange(up, dd.neighbor(dim, 1), dd.neighbor(dim, 0), dd.comm()));
      int64_t outside = 0;
      for (int i = 0; i < atoms.nlocal; ++i) outside += direction(atoms.x[i][dim], dim, dd) != 0;
      MPI_Allreduce(MPI_IN_PLACE, &outside, 1, MPI_INT64_T, MPI_SUM, dd.comm());
      if (outside == 0) {
        if (hop > stats.max_hops) stats.max_hops = hop;
        break;
      }
      if (hop > dd.dims()[dim]) {
        std::ostringstream msg;
        msg << "step " << step << ": " << outside << " atoms could not reach their subdomain along"
            << " axis "
            << "xyz"[dim] << " after " << hop
            << " hops; the integration is probably unstable: use a smaller --dt or --relax";
        throw MdError(msg.str());
      }
    }
  }
  return stats;
}

void check_atom_count(const Atoms &atoms, MPI_Comm comm, int64_t expected, int64_t step) {
  int64_t total = atoms.nlocal;
  MPI_Allreduce(MPI_IN_PLACE, &total, 1, MPI_INT64_T, MPI_SUM, comm);
  if (total != expected) {
    std::ostringstream msg;
    msg << "step " << step << ": the ranks own " << total << " atoms after migration, expected "
        << expected << " (" << (total < expected ? "lost " : "duplicated ")
        << std::llabs(total - expected) << "). This is a bug in mini_md; please report it.";
    throw MdError(msg.str());
  }
}

}  // namespace mini_md
