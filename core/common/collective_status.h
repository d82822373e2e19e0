// Agreeing on one outcome across ranks, so that a failure on one rank makes every rank skip the
// same collective steps (no rank is left waiting) and return the same status.
#pragma once

#include <mpi.h>

#include "core/common/status.h"

namespace lantern {

// Collective: returns the status of the lowest-numbered failing rank (code and message), or OK.
Status agree_on_status(MPI_Comm comm, const Status &local);

// Collective: every rank gets root's status.
Status broadcast_status(MPI_Comm comm, const Status &status, int root);

}  // namespace lantern
