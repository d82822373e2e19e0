#include "mpi_bootstrap.h"

#include <cstdlib>

#include "lantern/lantern.h"

namespace lantern {
namespace {
// MPI started by Lantern is finalised at process exit, not when the last context closes, so a
// serial host may close and reopen Lantern contexts as often as it likes.
void finalize_at_exit() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}
}  // namespace

std::string acquire_mpi(int mpi_comm_f, MPI_Comm *comm) {
  int initialized = 0, finalized = 0;
  MPI_Initialized(&initialized);
  MPI_Finalized(&finalized);
  if (finalized) return "MPI is already finalized; open Lantern contexts before MPI_Finalize";
  if (!initialized) {
    int provided = 0;
    if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
      return "MPI_Init_thread failed (Lantern initialises MPI when the host has not)";
    std::atexit(finalize_at_exit);
  }
  if (mpi_comm_f == LANTERN_COMM_WORLD) {
    *comm = MPI_COMM_WORLD;
  } else {
    *comm = MPI_Comm_f2c(mpi_comm_f);
    int size = 0;
    if (*comm == MPI_COMM_NULL || MPI_Comm_size(*comm, &size) != MPI_SUCCESS)
      return "mpi_comm_f: " + std::to_string(mpi_comm_f) +
             " is not a valid communicator handle (pass MPI_Comm_c2f(comm) or LANTERN_COMM_WORLD)";
  }
  return {};
}

}  // namespace lantern
