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

// MPI reports an invalid communicator handle through MPI_COMM_WORLD's error handler, fatal by
// default (an abort: the whole job ends on a wrong integer). The handle is checked with that
// handler set to MPI_ERRORS_RETURN, and the host's handler is put back.
std::string check_communicator(MPI_Comm comm, int mpi_comm_f) {
  const std::string named = "mpi_comm_f: " + std::to_string(mpi_comm_f);
  if (comm == MPI_COMM_NULL)
    return named + " is MPI_COMM_NULL (pass MPI_Comm_c2f(comm) or LANTERN_COMM_WORLD)";
  MPI_Errhandler host = MPI_ERRHANDLER_NULL;
  MPI_Comm_get_errhandler(MPI_COMM_WORLD, &host);
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  int size = 0, inter = 0;
  const bool valid =
      MPI_Comm_size(comm, &size) == MPI_SUCCESS && MPI_Comm_test_inter(comm, &inter) == MPI_SUCCESS;
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, host);
  MPI_Errhandler_free(&host);
  if (!valid)
    return named +
           " is not a valid communicator handle (pass MPI_Comm_c2f(comm) or LANTERN_COMM_WORLD)";
  if (inter)
    return named +
           " is an intercommunicator; Lantern renders over an intracommunicator (the ranks that "
           "hold the particles; e.g. MPI_Intercomm_merge it first)";
  return {};
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
    return {};
  }
  *comm = MPI_Comm_f2c(mpi_comm_f);
  return check_communicator(*comm, mpi_comm_f);
}

}  // namespace lantern
