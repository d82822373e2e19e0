// MPI for hosts that did not initialise it (a serial code linking Lantern): Lantern starts MPI
// on the first lantern_open() and finalises it at process exit.
#pragma once

#include <mpi.h>

#include <string>

namespace lantern {

// Ensures MPI is usable and resolves the Fortran handle (or LANTERN_COMM_WORLD) to a
// communicator. Returns "" or an error naming mpi_comm_f: MPI finalized, a handle that is not a
// communicator (checked without MPI's fatal error handler), or an intercommunicator. Local.
std::string acquire_mpi(int mpi_comm_f, MPI_Comm *comm);

}  // namespace lantern
