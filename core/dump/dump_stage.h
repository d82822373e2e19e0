// The dump stage of the pipeline: on the steps `dump.schedule` selects, appends the published
// particles to the H5MD file of `dump.file` (h5md_writer.h). Owned by Runtime.
//
// Collective over the runtime's communicator; every rank returns the same status. The file is
// created on the first dump with the fields of that step, or, with dump.mode: append, the first
// dump continues the time series of the file already there (a restarted run: frames whose step
// is not after the file's last step are refused, with an error for that step); dump.mode:
// create (the default) refuses a file already there, overwrite replaces it. The particle count
// may change from dump to dump. If creating the file fails, the next scheduled
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
#include "core/particles/bond_arrays.h"
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

  // Collective, at lantern_open: what dump.mode says of a file already at dump.file, checked at
  // once (the first dump may be hours away). create: kConfig naming dump.mode; append: kConfig
  // unless it is one of Lantern's H5MD files with the configured precision (and fields, when
  // listed). Every rank returns rank 0's outcome.
  Status check_existing_file(MPI_Comm comm) const;

  // Collective. `global` is the step's extent reduced over ranks (the pipeline computes it once
  // per step). `box` is this rank's lantern_set_box() box; without one (on rank 0) the dump
  // records the global bounds of the particles, non-periodic. `bonds` (this rank's, possibly
  // none): when some rank has bonds at the first dump, the file gets H5MD's connectivity
  // (/connectivity/all_bonds, by particle id; needs the id field) and every frame records the
  // frame's bonds there, each once over all ranks; a file created without bonds stays without.
  Status write(MPI_Comm comm, const ParticleArrays &particles, const BondArrays &bonds,
               const Extent &global, const std::optional<Box> &box, int64_t step, double time);

 private:
  Status open_writer(MPI_Comm comm, const ParticleArrays &particles, const BondArrays &bonds,
                     const Box &box, int64_t first_count, int64_t step);
  // dump.mode: append onto an existing file: its layout checked against the run's, a failed
  // frame cut back, the writer opened after its frames. Collective.
  Status append_to_existing(MPI_Comm comm, int fields, int64_t first_count, int64_t step);

  DumpConfig config_;
  std::unique_ptr<H5mdWriter> writer_;
  bool stopped_ = false;  // a frame failed: the dump is off for the rest of the run
  // Appending to an earlier run's file: its last step (frames at or before it are refused), and
  // its last frame's particle count (a first frame of another count is warned about).
  std::optional<int64_t> appended_after_step_;
  int64_t appended_after_count_ = -1;
};

}  // namespace lantern
