#include "stability.h"

#include <climits>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "md_error.h"

namespace mini_md {

namespace {

bool finite3(const Vec3 &a) {
  return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]);
}

std::string vec_text(const Vec3 &a) {
  std::ostringstream s;
  s << "(" << a[0] << ", " << a[1] << ", " << a[2] << ")";
  return s.str();
}

std::string remedy(double dt) {
  std::ostringstream s;
  s << "The integration is unstable: use a smaller --dt (now " << dt
    << "), or --relax if the start has overlapping atoms.";
  return s.str();
}

// The rank with `owner` true composes the message; every rank receives it. Collective.
std::string share_message(const std::string &local, bool owner, MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  int root = owner ? rank : -1;
  MPI_Allreduce(MPI_IN_PLACE, &root, 1, MPI_INT, MPI_MAX, comm);
  if (root < 0) return {};
  int length = owner && rank == root ? static_cast<int>(local.size()) : 0;
  MPI_Bcast(&length, 1, MPI_INT, root, comm);
  std::vector<char> text(local.begin(), local.end());
  text.resize(length);
  MPI_Bcast(text.data(), length, MPI_CHAR, root, comm);
  return std::string(text.begin(), text.end());
}

}  // namespace

void raise_nonfinite(const Atoms &atoms, MPI_Comm comm, int64_t step, double dt) {
  int local = -1;
  for (int i = 0; i < atoms.nlocal; ++i) {
    if (!finite3(atoms.x[i]) || !finite3(atoms.v[i]) || !finite3(atoms.f[i])) {
      if (local < 0 || atoms.id[i] < atoms.id[local]) local = i;
    }
  }
  int64_t first = local >= 0 ? atoms.id[local] : INT64_MAX;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT64_T, MPI_MIN, comm);
  const bool owner = local >= 0 && atoms.id[local] == first;
  std::string text;
  if (owner) {
    const char *what = !finite3(atoms.f[local])   ? "force"
                       : !finite3(atoms.v[local]) ? "velocity"
                                                  : "position";
    std::ostringstream msg;
    msg << "step " << step << ": atom " << first << " has a non-finite " << what
        << " (x = " << vec_text(atoms.x[local]) << ", v = " << vec_text(atoms.v[local])
        << ", f = " << vec_text(atoms.f[local]) << "). " << remedy(dt);
    text = msg.str();
  }
  text = share_message(text, owner, comm);
  if (text.empty()) {
    std::ostringstream msg;
    msg << "step " << step << ": a non-finite value appeared. " << remedy(dt);
    text = msg.str();
  }
  throw MdError(text);
}

namespace {

// Id and speed of the fastest owned atom over all ranks, in a message fragment. Collective.
std::string fastest_atom(const Atoms &atoms, MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  struct {
    double v2;
    int rank;
  } best{-1.0, rank};
  int local = -1;
  for (int i = 0; i < atoms.nlocal; ++i) {
    const Vec3 &v = atoms.v[i];
    const double v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if (v2 > best.v2) {
      best.v2 = v2;
      local = i;
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, &best, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm);
  const bool owner = best.rank == rank && local >= 0;
  std::string text;
  if (owner) {
    std::ostringstream s;
    s << "fastest atom " << atoms.id[local] << " at x = " << vec_text(atoms.x[local])
      << " moves at |v| = " << std::sqrt(best.v2);
    text = s.str();
  }
  return share_message(text, owner, comm);
}

}  // namespace

void raise_runaway(const Atoms &atoms, MPI_Comm comm, int64_t step, double dt, double displacement,
                   double limit) {
  std::ostringstream msg;
  msg << "step " << step << ": an atom moved " << displacement
      << " in one step, more than cutoff + skin = " << limit << "; " << fastest_atom(atoms, comm)
      << ". " << remedy(dt);
  throw MdError(msg.str());
}

void check_energy_blowup(const Atoms &atoms, MPI_Comm comm, const ThermoState &now, double e0_atom,
                         double limit, double dt) {
  if (std::fabs(now.e_conserved_atom - e0_atom) <= limit) return;
  std::ostringstream msg;
  msg << "step " << now.step << ": energy blow-up, E/atom (shifted potential) went from " << e0_atom
      << " to " << now.e_conserved_atom << " (limit +-" << limit << ", --blowup-energy); "
      << fastest_atom(atoms, comm) << ". " << remedy(dt);
  throw MdError(msg.str());
}

void check_temperature_blowup(const Atoms &atoms, MPI_Comm comm, const ThermoState &now,
                              double limit, double dt) {
  if (now.temperature <= limit) return;
  std::ostringstream msg;
  msg << "step " << now.step << ": temperature blow-up, T = " << now.temperature << " exceeds "
      << limit << "; " << fastest_atom(atoms, comm) << ". " << remedy(dt);
  throw MdError(msg.str());
}

}  // namespace mini_md
