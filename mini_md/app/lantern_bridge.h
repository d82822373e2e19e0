// LanternBridge: mini_md's in-situ consumer. It hands Lantern mini_md's own arrays in place
// (interleaved double x[N][3], the per-atom kinetic-energy scalar and int32 types; no copies)
// through the public C API only, re-publishing whenever the simulation reallocates or migrates.
#pragma once

#include <lantern/lantern.h>
#include <mpi.h>

#include <string>

#include "box.h"
#include "step_observer.h"

namespace mini_md {

class LanternBridge : public StepObserver {
 public:
  // Opens a Lantern context on `comm` (collective). Throws MdError if Lantern rejects the
  // configuration: the user asked for rendering, so running without it would be a surprise.
  LanternBridge(const std::string &config, MPI_Comm comm);
  ~LanternBridge() override;
  LanternBridge(const LanternBridge &) = delete;
  LanternBridge &operator=(const LanternBridge &) = delete;

  // Tells Lantern the simulation box (lantern_set_box): the `box:` overlay draws it, dumps record
  // it and bonds use its periodic axes. mini_md's box never changes during a run, so once is
  // enough. Local; every rank passes the same box.
  void set_box(const Box &box);
  void on_publish(const Atoms &atoms) override;
  void on_step(int64_t step, double time) override;
  int failures() const { return failures_; }
  // Lantern's per-rank load of the last rendered step (lantern_load_summary): rank 0, with stats
  // on; "" otherwise.
  std::string load_summary() const { return ctx_ ? lantern_load_summary(ctx_) : ""; }

 private:
  void report(const char *call, lantern_status status);

  lantern_context *ctx_ = nullptr;
  int rank_ = 0;
  int failures_ = 0;
};

}  // namespace mini_md
