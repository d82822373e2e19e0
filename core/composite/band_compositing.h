// Compositing that ends with every rank holding its own row band of the merged frame, instead of
// the whole merged frame on a root: for stages that work band by band after compositing
// (super-sampling's down-sampling), it saves gathering the frame on the root and handing it out
// again.
//
// Method: active pixels (active_pixel_compositing.h) along the cost model's cheapest radix-k
// schedule, whose final blocks are the row bands row_band(height, ranks, k, multiple)
// (row_bands.h) - with folding, a base rank ends holding its own band and its extra rank's, and
// hands the latter back. Or, on request (kDirectSend), dense direct send over the bands, every
// pixel of every band moving. Both merge by compositing's rule (packed_pixel.h: nearer depth,
// then smaller color), which is commutative and associative, so every band is bit-identical to
// the same rows of composite_frames' result, at any rank count and split.
//
// Collective: every rank calls with frames of the same size and the same multiple. Problems found
// before any pixel moves (sizes differ, a frame inconsistent or above INT_MAX / 4 pixels, out of
// memory for the scratch) are agreed in one MPI_Allreduce and returned as the same kMpi status on
// every rank. Memory: about two chunks of scratch (kDefaultCompositeChunkPixels) besides the frame.
#pragma once

#include <mpi.h>

#include "core/common/status.h"
#include "core/composite/depth_compositor.h"
#include "core/composite/row_bands.h"
#include "core/view/frame.h"

namespace lantern {

// Merges every rank's `frame` so that on return rows *owned (row_band(frame.height, ranks, rank,
// multiple)) of this rank's frame hold the merged image; its other rows are unspecified.
// `multiple` must divide frame.height. With one rank this is a no-op (owned: every row).
// options.method: kAuto or kActivePixels (stats: method "active_pixels_bands" and the schedule),
// or kDirectSend (method "direct_send_bands"); any other is refused (kInvalidArgument, on every
// rank alike, before any communication). OK or kMpi (the same on every rank); fills *stats if
// not null.
Status composite_to_row_bands(MPI_Comm comm, Frame &frame, int multiple, RowBand *owned,
                              const CompositeOptions &options, CompositeStats *stats = nullptr);

// The same with the default options.
inline Status composite_to_row_bands(MPI_Comm comm, Frame &frame, int multiple, RowBand *owned,
                                     CompositeStats *stats = nullptr) {
  return composite_to_row_bands(comm, frame, multiple, owned, CompositeOptions(), stats);
}

}  // namespace lantern
