#include "simulation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "integrator.h"
#include "langevin.h"
#include "md_error.h"
#include "memory_check.h"
#include "migration.h"
#include "relax.h"
#include "stability.h"

namespace mini_md {

Simulation::Simulation(const RunConfig &cfg, MPI_Comm comm) : cfg_(cfg), scene_(define_scene(cfg)) {
  if (!(cfg_.dt > 0)) throw MdError("--dt must be positive");
  if (!(cfg_.cutoff > 0) || !(cfg_.skin >= 0)) throw MdError("--cutoff must be > 0, --skin >= 0");
  if (cfg_.neigh_every < 1) throw MdError("--neigh-every must be at least 1");
  check_memory(cfg_, comm);  // before any atom is made
  dd_ = std::make_unique<DomainDecomposition>(comm, scene_.box, ghost_cut());
  is_root_ = dd_->rank() == 0;
  const double t0 = MPI_Wtime();
  create_scene_atoms(cfg_, scene_, *dd_, atoms_);
  natoms_ = atoms_.nlocal;
  MPI_Allreduce(MPI_IN_PLACE, &natoms_, 1, MPI_INT64_T, MPI_SUM, dd_->comm());
  if (natoms_ < 2) throw MdError("the scene holds fewer than 2 atoms; increase --cells");
  counters_.setup_seconds += MPI_Wtime() - t0;
}

double Simulation::charge(double *phase, double t0) {
  const double now = MPI_Wtime();
  if (in_loop_) *phase += now - t0;
  return now;
}

void Simulation::notify_publish() {
  if (observer_ == nullptr) return;
  const double t0 = MPI_Wtime();
  observer_->on_publish(atoms_);
  charge(&counters_.insitu_seconds, t0);
}

void Simulation::notify_step() {
  if (observer_ == nullptr) return;
  // The rendered scalar: kinetic energy per atom, which lights up shocks and hot spots.
  for (int i = 0; i < atoms_.nlocal; ++i) {
    const Vec3 &v = atoms_.v[i];
    atoms_.scalar[i] = 0.5 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  const double t0 = MPI_Wtime();
  observer_->on_step(step_, static_cast<double>(step_) * cfg_.dt);
  charge(&counters_.insitu_seconds, t0);
}

void Simulation::rebuild() {
  double t = MPI_Wtime();
  atoms_.clear_ghosts();
  const MigrationStats moved = migrate_atoms(atoms_, *dd_, step_);
  check_atom_count(atoms_, dd_->comm(), natoms_, step_);
  counters_.migrated += moved.moved;
  counters_.max_hops = std::max(counters_.max_hops, moved.max_hops);
  t = charge(&counters_.comm_seconds, t);
  if (cfg_.sort_every > 0 && counters_.rebuilds % cfg_.sort_every == 0) {
    atoms_.permute_owned(spatial_sort_order(atoms_, dd_->sub_lo(), dd_->sub_hi(), ghost_cut()));
  }
  t = charge(&counters_.neighbor_seconds, t);
  ghosts_.borders(atoms_, *dd_, ghost_cut());
  t = charge(&counters_.comm_seconds, t);
  list_.build(atoms_, dd_->sub_lo(), dd_->sub_hi(), ghost_cut());
  std::copy(atoms_.x.begin(), atoms_.x.begin() + atoms_.nlocal, atoms_.x_build.begin());
  charge(&counters_.neighbor_seconds, t);
  last_build_ = step_;
  ++counters_.rebuilds;
  notify_publish();
}

PairTally Simulation::compute_forces(bool tally) {
  double t = MPI_Wtime();
  const PairTally pairs = compute_lj_forces(
      atoms_, list_, cfg_.cutoff, cfg_.shift_energy ? lj_energy_at(cfg_.cutoff) : 0.0, tally);
  t = charge(&counters_.force_seconds, t);
  ghosts_.reverse_forces(atoms_);
  charge(&counters_.comm_seconds, t);
  return pairs;
}

PairTally Simulation::compute_capped_forces(double r_cap) {
  const PairTally pairs = compute_capped_lj_forces(atoms_, list_, cfg_.cutoff, r_cap);
  ghosts_.reverse_forces(atoms_);
  return pairs;
}

double Simulation::global_max_displacement2() const {
  double m = 0.0;
  for (int i = 0; i < atoms_.nlocal; ++i) {
    const Vec3 &x = atoms_.x[i], &b = atoms_.x_build[i];
    const double dx = x[0] - b[0], dy = x[1] - b[1], dz = x[2] - b[2];
    m = std::max(m, dx * dx + dy * dy + dz * dz);
  }
  MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_MAX, dd_->comm());
  return m;
}

void Simulation::setup() {
  const double t0 = MPI_Wtime();
  if (is_root_ && cfg_.print_thermo) {
    std::printf("mini_md: %s; %lld atoms on %d ranks (grid %dx%dx%d); box %.6g x %.6g x %.6g\n",
                scene_.description.c_str(), static_cast<long long>(natoms_), dd_->size(),
                dd_->dims()[0], dd_->dims()[1], dd_->dims()[2], scene_.box.length(0),
                scene_.box.length(1), scene_.box.length(2));
    std::printf("mini_md: LJ cutoff %g (energies %s), skin %g, dt %g, rebuild every %d steps%s\n",
                cfg_.cutoff, cfg_.shift_energy ? "shifted to 0 at the cutoff" : "unshifted",
                cfg_.skin, cfg_.dt, cfg_.neigh_every,
                cfg_.neigh_check ? " or when an atom moved skin/2" : "");
  }
  if (cfg_.relax) {
    const RelaxResult r = relax_positions(*this, cfg_.relax_steps, cfg_.relax_fmax);
    counters_.relax_iterations = r.iterations;
    if (is_root_ && cfg_.print_thermo) {
      std::printf("mini_md: relax: %d iterations, max |f| %.4g, capped PE/atom %.6g%s\n",
                  r.iterations, r.max_force, r.pe_atom,
                  r.converged ? "" : " (NOT converged: raise --relax-steps)");
    }
  }
  assign_scene_velocities(cfg_, scene_, atoms_, dd_->comm());
  step_ = 0;
  rebuild();
  const PairTally pairs = compute_forces(true);
  counters_.setup_seconds += MPI_Wtime() - t0;
  if (is_root_ && cfg_.print_thermo) std::printf("%s\n", thermo_header().c_str());
  record_thermo(pairs);
  e0_atom_ = thermo_.back().e_conserved_atom;
  notify_step();
  std::fflush(stdout);
}

void Simulation::record_thermo(const PairTally &pairs) {
  const double cutoff_energy = lj_energy_at(cfg_.cutoff);
  const ThermoState t =
      reduce_thermo(atoms_, pairs, natoms_, scene_.box.volume(),
                    cfg_.shift_energy ? cutoff_energy : 0.0, cutoff_energy, dd_->comm(), step_);
  if (!std::isfinite(t.etot_atom) || !std::isfinite(t.pressure)) {
    raise_nonfinite(atoms_, dd_->comm(), step_, cfg_.dt);
  }
  thermo_.push_back(t);
  if (is_root_ && cfg_.print_thermo) std::printf("%s\n", format_thermo(t).c_str());
  if (thermo_.size() == 1) {  // step 0 defines the references
    runaway_.emplace(t, std::max(scene_.temperature, cfg_.langevin_temp.value_or(0.0)));
    return;
  }
  if (cfg_.langevin_temp) {
    const double limit = 100.0 * std::max({*cfg_.langevin_temp, scene_.temperature, 1.0});
    check_temperature_blowup(atoms_, dd_->comm(), t, limit, cfg_.dt);
  } else {
    check_energy_blowup(atoms_, dd_->comm(), t, e0_atom_, cfg_.blowup_energy, cfg_.dt);
  }
  warn_if_runaway(t);
}

void Simulation::warn_if_runaway(const ThermoState &t) {
  // The thermo is reduced over ranks, so every rank finds the same warnings; rank 0 prints.
  for (const std::string &warning : runaway_->check(t)) {
    warnings_.push_back(warning);
    if (is_root_) {
      std::fflush(stdout);
      std::fprintf(stderr, "mini_md: warning: %s\n", warning.c_str());
    }
  }
}

void Simulation::step_once(bool last) {
  ++step_;
  const DriftReport drift = initial_integrate(atoms_, scene_.box, cfg_.dt, cfg_.neigh_check);
  // One allreduce per step carries both the rebuild criterion and the safety flag.
  double flags[2] = {drift.max_displacement2, (drift.finite && velocities_finite_) ? 0.0 : 1.0};
  MPI_Allreduce(MPI_IN_PLACE, flags, 2, MPI_DOUBLE, MPI_MAX, dd_->comm());
  if (flags[1] > 0) raise_nonfinite(atoms_, dd_->comm(), step_, cfg_.dt);
  // Rebuilds follow any move beyond skin/2, so a larger displacement happened within one step:
  // the dynamics is no longer resolved.
  if (cfg_.neigh_check && flags[0] > ghost_cut() * ghost_cut()) {
    raise_runaway(atoms_, dd_->comm(), step_, cfg_.dt, std::sqrt(flags[0]), ghost_cut());
  }
  const double half_skin = 0.5 * cfg_.skin;
  if (step_ - last_build_ >= cfg_.neigh_every ||
      (cfg_.neigh_check && flags[0] > half_skin * half_skin)) {
    rebuild();
  } else {
    const double t = MPI_Wtime();
    refresh_ghosts();
    charge(&counters_.comm_seconds, t);
  }
  const bool thermo_due = last || (cfg_.thermo_every > 0 && step_ % cfg_.thermo_every == 0);
  const PairTally pairs = compute_forces(thermo_due);
  if (cfg_.langevin_temp) {
    apply_langevin(atoms_, *cfg_.langevin_temp, cfg_.langevin_damp, cfg_.dt, cfg_.seed, step_);
  }
  velocities_finite_ = final_integrate(atoms_, cfg_.dt);
  if (thermo_due) record_thermo(pairs);
  notify_step();
}

void Simulation::run(int64_t steps) {
  in_loop_ = true;
  const double t0 = MPI_Wtime();
  for (int64_t s = 0; s < steps; ++s) step_once(s + 1 == steps);
  counters_.loop_seconds += MPI_Wtime() - t0;
  in_loop_ = false;
  std::fflush(stdout);
}

}  // namespace mini_md
