// Point-to-point building blocks of the hand-written compositing methods (binary swap, direct
// send): frames are merged in place, pixel ranges travel as separate depth and color messages,
// and the received side goes through a scratch segment of at most one chunk.
//
// Messages use four tags from 0x4c43 ("LC") on comm; a caller that sends its own messages on the
// same communicator should give compositing a duplicate (MPI_Comm_dup), as the pipeline does.
#pragma once

#include <mpi.h>

#include <cstddef>
#include <vector>

#include "core/common/status.h"
#include "core/composite/composite_methods.h"
#include "core/composite/pixel_range.h"
#include "core/view/frame.h"

namespace lantern {

// Sends the pixels `give` of frame to rank send_to (if give is not empty) while receiving rank
// recv_from's pixels for `keep` (if keep is not empty) and merging them into frame. The matching
// call on the other side must use the same range: its keep is our give. Ranges are cut into
// scratch-sized segments that move in lockstep, one segment pair in flight at a time.
// Adds the messages and bytes to *traffic. OK or kMpi.
Status exchange_and_merge(MPI_Comm comm, int send_to, PixelRange give, int recv_from,
                          PixelRange keep, Frame &frame, MethodScratch &scratch,
                          CompositeTraffic *traffic);

// Gathers owned[i] from every rank i into root's frame; root's own range is already in place.
// Adds the messages and bytes to *traffic. OK or kMpi.
Status gather_ranges(MPI_Comm comm, int root, const std::vector<PixelRange> &owned, Frame &frame,
                     CompositeTraffic *traffic);

}  // namespace lantern
