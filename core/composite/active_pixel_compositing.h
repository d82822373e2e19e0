// Active-pixel compositing: a radix-k schedule (compositing_schedule.h) run over frames whose
// empty pixels are never sent (active_pixels.h, run_length_pixels.h) - the combination IceT
// settled on at scale (Moreland, Kendall, Peterka and Huang, "An Image Compositing Solution at
// Scale", SC 2011; radix-k: Peterka et al., SC 2009).
//
// Phases, each an exchange_active_pixels (active_pixel_exchange.h) with its own tag:
//   fold    extra ranks stream their whole frame to their group's base rank, which merges it;
//   rounds  the base ranks run the schedule's rounds, merging in place;
//   finish  to a root: every base rank streams its block to the root, which merges it; to bands:
//           every base rank already holds its own band, and streams its extra rank's band back.
// The tree reduce (to a root only) is its rounds alone.
// Bytes moved per rank follow what the ranks drew, not the frame: a rank that drew a tenth of the
// image sends about a tenth of what dense binary swap sends in its first round.
//
// Collective over comm; every rank passes the same plan (a pure function of agreed values).
#pragma once

#include <mpi.h>

#include <vector>

#include "core/common/status.h"
#include "core/composite/active_pixel_exchange.h"
#include "core/composite/active_pixels.h"
#include "core/composite/composite_traffic.h"
#include "core/composite/compositing_schedule.h"
#include "core/composite/pixel_range.h"

namespace lantern {

struct ActivePixelPlan {
  CompositingSchedule schedule;
  std::vector<PixelRange> blocks;  // schedule.base() contiguous ranges in order: group g's block
  // Where the merged frame ends: on `root` (bands empty), or rank r holding bands[r] (one range per
  // rank, inside its group's block; root unused).
  int root = 0;
  std::vector<PixelRange> bands;
};

// Runs the plan on this rank's scanned frame. OK, or the first failing phase's status (kMpi, or
// kInternal for a malformed message); the later phases still run, so no rank is left waiting.
Status run_active_pixel_plan(MPI_Comm comm, const ActivePixelPlan &plan, ActiveFrame &frame,
                             ActivePixelScratch &scratch, CompositeTraffic *traffic);

}  // namespace lantern
