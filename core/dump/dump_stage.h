// The dump stage of the pipeline: on the steps `dump.schedule` selects, appends the published
// particles to the H5MD file of `dump.file` (h5md_writer.h). Owned by Runtime.
//
// Collective over the runtime's communicator; every rank returns the same status. The file is
// created on the first dump (replacing an existing one) with the fields of that step; the
// particle count may change from dump to dump. If creating the file fails, the next scheduled
// dump tries again (there is nothing to lose). If appending a frame fails on any rank (disk
// full, permissions changed, an HDF5 error), every rank returns the same kIo status naming the
// file, the file is closed on every rank (it keeps every earlier
// frame) and the dump is off for the rest of the run: later scheduled dumps are skipped and
// return OK, so rendering continues (reopening could not be made safe after a collective
// failure, and recreating the file would erase it).
#pragma once

#include <mpi.h>

#include <memory>
#include <optional>

#include "core/common/status.h"
#include "core/config/config.h"
#include "core/dump/box.h"
#include "core/dump/h5md_writer.h"
#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"

namespace lantern {

class DumpStage {
 public:
  explicit DumpStage(DumpConfig config) : config_(std::move(config)) {}
  bool due(int64_t step) const {
    return config_.enabled && !stopped_ && config_.schedule.due(step);
  }
  // A new dump.schedule from a live reconfiguration (the file and its fields stay).
  void set_schedule(const Schedule &schedule) { config_.schedule = schedule; }

  // Collective. `global` is the step's extent reduced over ranks (the pipeline computes it once
  // per step). `box` is this rank's lantern_set_box() box; without one (on rank 0) the dump
  // records the global bounds of the particles, non-periodic.
  Status write(MPI_Comm comm, const ParticleArrays &particles, const Extent &global,
               const std::optional<Box> &box, int64_t step, double time);

 private:
  Status open_writer(MPI_Comm comm, const ParticleArrays &particles, const Box &box,
                     int64_t first_count, int64_t step);

  DumpConfig config_;
  std::unique_ptr<H5mdWriter> writer_;
  bool stopped_ = false;  // a frame failed: the dump is off for the rest of the run
};

}  // namespace lantern
