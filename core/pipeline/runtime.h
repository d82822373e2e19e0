// Everything behind one lantern_context: the configuration, the communicator, the published
// particles and the per-step pipeline. The C API (adaptor/) is a thin, exception-proof shell
// around this class.
//
// Ownership: owns a duplicate of the caller's communicator and borrows the particle arrays.
// Thread-safety: one thread at a time (lantern_publish in the C API).
#pragma once

#include <mpi.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/config/config.h"
#include "core/dump/box.h"
#include "core/dump/dump_stage.h"
#include "core/particles/bond_arrays.h"
#include "core/particles/particle_arrays.h"
#include "core/particles/periodic_box.h"
#include "core/pipeline/config_watch.h"
#include "core/pipeline/scene_pass.h"
#include "core/render/gl/gl_session.h"

namespace lantern {

class Runtime {
 public:
  // Collective over comm. On failure returns the (agreed) status and leaves *out empty.
  // `caller`: a failure of this rank's own arguments (a NULL from the C API), agreed with the
  // others like a configuration error, so that no rank returns before the collective open.
  static Status open(const std::string &config, MPI_Comm comm, std::unique_ptr<Runtime> *out,
                     const Status &caller = Status());
  ~Runtime();
  Runtime(const Runtime &) = delete;
  Runtime &operator=(const Runtime &) = delete;

  Status publish(const ParticleDescription &particles);  // local; forgets the bonds
  // Local: the bonds of the particles last published (lantern_publish_bonds). On failure this
  // rank has no bonds until the next successful call.
  Status publish_bonds(const BondDescription &bonds);
  Status execute(int64_t step, double time);  // collective on scheduled steps
  // Waits for images still being written in the background; collective, same status on every
  // rank. Called by lantern_close before the Runtime is destroyed.
  Status finish();
  Status set_box(const Box &box);  // local; recorded with particle dumps, bonds' minimum image
  // Replaces the configuration (lantern_reconfigure; runtime_reconfigure.cpp). Collective; every
  // rank returns the same status, and on failure the running configuration stays. nullopt (a
  // NULL from the C API) fails on every rank with kNullArgument.
  Status reconfigure(const std::optional<std::string> &config);
  // How many times a new configuration took effect since open (a no-op edit does not count).
  int64_t configuration_changes() const { return config_changes_; }

  const Config &config() const { return config_; }
  // Rank 0, with stats on: the per-rank spread of the last rendered step, a header line and one
  // line per scene (SceneStats::per_rank_line); "" elsewhere or before the first rendered step.
  const std::string &load_summary() const { return load_summary_; }
  MPI_Comm communicator() const { return comm_; }

 private:
  Runtime() = default;
  // The GL session the configuration and environment ask for, or none (then the CPU raster
  // draws); collective, with the outcome agreed. Warns once on rank 0 when it falls back.
  Status open_gl();
  // OK while MPI runs; kMpi once the host called MPI_Finalize with this context still open
  // (then no collective call may be made: MPI would abort). Local.
  Status mpi_usable(const char *function) const;
  void warn_nonfinite_once(int64_t count, int64_t step);
  // Once, collective: rank 0 warns when scenes draw bonds but no rank published any.
  void warn_if_no_bonds_given(int64_t step);
  // Rank 0: what the configuration's scenes ask that Lantern can only clamp (a density.range
  // beyond double precision), once per configuration (at open and at each change).
  void warn_about_scenes() const;
  // Rank 0, at open: the hidden temporary files a killed earlier run left in the scenes' output
  // folders are removed (atomic_file.h: only Lantern's temporary names, only files older than
  // this process, only of processes not running here).
  void remove_stale_temporaries_of_outputs() const;
  // Live configuration (runtime_reconfigure.cpp). load_first_config: lantern_open's config into
  // config_ (local). switch_config: collective, `text` the same on every rank. follow_config_file:
  // collective, on scheduled steps while watching; true when a new configuration took effect.
  Status load_first_config(const std::string &path_or_document);
  Status agree_on_first_config();  // collective: every rank loaded the same text
  Status switch_config(const std::string &text, const std::string &path, uint64_t hash);
  bool follow_config_file(int64_t step);
  // Appends the step's stats line (rank 0) reporting `status`, the status execute() returns.
  // Collective when a stats file is configured: every rank gets rank 0's outcome (kIo naming the
  // file when it cannot be written).
  // budget_ms / budget_percent: this step's budget of scene s (NaN: none known yet), and the
  // record of what the budgeted scenes cost (collective: one reduction of the slowest rank's
  // costs and of the gap before this step, so every rank's controllers see the same numbers).
  double scene_budget_ms(size_t s) const;
  void record_scene_costs(double gap_ms, const std::vector<bool> &rendered,
                          std::vector<SceneStats> *stats);
  Status write_stats(int64_t step, double time, const Extent &global, double total_ms,
                     const std::vector<SceneStats> &scenes, const Status &status);

  Config config_;
  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0, size_ = 1;
  ParticleArrays particles_;
  BondArrays bonds_;               // count 0: no bonds
  uint64_t bonds_serial_ = 0;      // bumped by every publish, so the step's half-bonds are rebuilt
  bool bonds_given_ = false;       // lantern_publish_bonds succeeded since the last publish
  bool bonds_checked_ = false;     // the first step with a bonds scene checked that some were
  std::shared_ptr<GlSession> gl_;  // null without OpenGL
  std::vector<SceneBuffers> buffers_;  // one per scene
  PassScratch scratch_;                // bricks and culling buffers, shared by the scenes
  bool warned_nonfinite_ = false;
  std::optional<Box> box_;  // lantern_set_box(); dumps use particle bounds without it
  std::optional<PeriodicBox> periodic_box_;  // box_'s axes for bonds' minimum image
  std::unique_ptr<DumpStage> dump_;          // null unless config_.dump.enabled
  // Live configuration: where the running configuration came from, for no-op detection and
  // `watch: true`; what the next stats line says about a reload (rank 0).
  std::string config_path_;   // "" for an inline document
  uint64_t config_hash_ = 0;  // content_hash of its text
  int64_t config_changes_ = 0;
  bool gl_tried_ = false;  // open_gl ran (it runs once, when the first scene appears)
  ConfigWatch watch_;
  std::string config_event_;  // "" or the stats line's config note (reloaded / error), rank 0
  std::string load_summary_;  // rank 0: see load_summary()
  // budget_percent: when the last rendering lantern_execute returned (this rank), and the wall
  // time before the last rendered step (ms, the slowest rank's; 0 before it is known).
  std::optional<std::chrono::steady_clock::time_point> last_render_end_;
  double render_gap_ms_ = 0.0;
};

}  // namespace lantern
