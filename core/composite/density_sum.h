// Compositing of density images (`style: density`) by sum: every rank's fixed-point
// DensityImage (core/render/density_splat.h) is added into the root's with MPI_Reduce(MPI_SUM)
// on int64. Integer addition is associative and commutative and the pixel sums are bounded below
// 2^63 (density_splat.h: at most 2^38 particles), so the result is the same bits for any number
// of ranks, any split and any reduction order - no wrap, no rounding.
//
// Collective over `comm`; every rank passes an image of the same size and channels. The image
// matters on root after the call (the other ranks' images are left as they were). Sent in
// chunks of 2^26 values (512 MiB), since MPI counts are int.
#pragma once

#include <mpi.h>

#include "core/common/status.h"
#include "core/render/density_splat.h"

namespace lantern {

Status sum_density_to_root(MPI_Comm comm, int root, DensityImage *image);

}  // namespace lantern
