// Simulation: one LJ run on a communicator, owning the atoms, the decomposition, the ghost
// exchange and the neighbour list, and stepping them with velocity Verlet.
//
// A step: half kick + drift; one allreduce (max displacement, non-finite flag); either a rebuild
// (migrate, check count, sort, ghosts, list) or a forward exchange of ghost positions; pair
// forces; reverse exchange of ghost forces; optional Langevin; half kick; thermo when due.
#pragma once

#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "atoms.h"
#include "domain_decomposition.h"
#include "ghost_exchange.h"
#include "lj_force.h"
#include "neighbor_list.h"
#include "run_config.h"
#include "runaway_watch.h"
#include "scenes.h"
#include "step_observer.h"
#include "thermo.h"

namespace mini_md {

struct RunCounters {
  int64_t rebuilds = 0;
  int64_t migrated = 0;  // atoms sent to another rank (this rank)
  int max_hops = 0;      // most subdomains an atom crossed along one axis between rebuilds
  int64_t relax_iterations = 0;
  double setup_seconds = 0.0;
  double loop_seconds = 0.0;  // wall time of the time-stepping loop (run())
  // loop_seconds by phase, as miniMD prints it. Only time inside run() counts: setup's rebuild,
  // forces and step-0 observer calls are not in these.
  double force_seconds = 0.0;     // pair forces
  double neighbor_seconds = 0.0;  // neighbour-list builds, with the spatial sort
  double comm_seconds = 0.0;      // ghost exchange (borders, forward, reverse) and migration
  double insitu_seconds = 0.0;    // time inside the observer (Lantern calls)
  // The rest of the loop (integration, thermo, the per-step allreduce, ...), never negative.
  double other_seconds() const {
    return std::max(
        0.0, loop_seconds - force_seconds - neighbor_seconds - comm_seconds - insitu_seconds);
  }
};

class Simulation {
 public:
  // Builds the scene's box, decomposition and atoms. Collective; throws MdError on every rank
  // for an impossible setup (box too small for the rank count, no atoms, ...).
  Simulation(const RunConfig &cfg, MPI_Comm comm);

  // The observer (not owned) sees every publish and step from now on.
  void set_observer(StepObserver *observer) { observer_ = observer; }
  // Step 0: optional --relax, velocities, first neighbour build, forces and thermo.
  void setup();
  // Advances `steps` steps from the current one.
  void run(int64_t steps);

  // Building blocks, public for relax and for tests.
  void rebuild();
  void refresh_ghosts() { ghosts_.forward_positions(atoms_); }
  PairTally compute_forces(bool tally);
  PairTally compute_capped_forces(double r_cap);
  double global_max_displacement2() const;

  Atoms &atoms() { return atoms_; }
  const Atoms &atoms() const { return atoms_; }
  const DomainDecomposition &domain() const { return *dd_; }
  const RunConfig &config() const { return cfg_; }
  const SceneSetup &scene() const { return scene_; }
  int64_t natoms() const { return natoms_; }
  int64_t current_step() const { return step_; }
  double ghost_cut() const { return cfg_.cutoff + cfg_.skin; }
  const std::vector<ThermoState> &thermo_log() const { return thermo_; }
  const RunCounters &counters() const { return counters_; }
  // Warnings of a runaway run (runaway_watch.h), in order; rank 0 also printed them to stderr.
  const std::vector<std::string> &warnings() const { return warnings_; }
  int64_t ghost_count() const { return ghosts_.ghost_count(); }
  size_t pair_count() const { return list_.pair_count(); }

 private:
  void step_once(bool last);
  void record_thermo(const PairTally &pairs);
  void warn_if_runaway(const ThermoState &t);
  void notify_publish();
  void notify_step();
  // Adds the time since t0 to *phase while run() steps; returns the current time.
  double charge(double *phase, double t0);

  RunConfig cfg_;
  SceneSetup scene_;
  std::unique_ptr<DomainDecomposition> dd_;
  Atoms atoms_;
  GhostExchange ghosts_;
  NeighborList list_;
  StepObserver *observer_ = nullptr;
  std::vector<ThermoState> thermo_;
  std::optional<RunawayWatch> runaway_;  // set from the step-0 thermo
  std::vector<std::string> warnings_;
  RunCounters counters_;
  int64_t natoms_ = 0;
  int64_t step_ = 0;
  int64_t last_build_ = 0;
  double e0_atom_ = 0.0;
  bool velocities_finite_ = true;
  bool is_root_ = false;
  bool in_loop_ = false;  // inside run(): phase times count
};

}  // namespace mini_md
