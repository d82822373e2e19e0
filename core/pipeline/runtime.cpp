#include "core/pipeline/runtime.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <utility>

#include "core/common/collective_status.h"
#include "core/common/ms_since.h"
#include "core/common/rank_threads.h"
#include "core/config/config_loader.h"
#include "core/config/enum_names.h"
#include "core/config/environment.h"
#include "core/config/file_pattern.h"
#include "core/finish/density_transfer.h"
#include "core/output/atomic_file.h"
#include "core/output/stats_writer.h"
#include "core/particles/particle_scan.h"
#include "core/particles/position_tap.h"
#include "core/pipeline/memory_budget.h"
#include "core/pipeline/scene_movie.h"
#include "core/pipeline/scene_overlays.h"
#include "core/render/object_occlusion.h"

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;

// Per-particle radii must be usable: finite and non-negative. OK, or kInvalidArgument naming the
// first offender. Particles outside the group (mask) are never drawn, so their radii are not read.
Status check_radii(const ParticleArrays &p) {
  if (!p.has_radius()) return {};
  for (int64_t i = 0; i < p.count(); ++i) {
    if (!p.kept(i)) continue;
    const double r = p.radius(i);
    if (!(r >= 0.0) || !std::isfinite(r))
      return {StatusCode::kInvalidArgument, "particles.radius[" + std::to_string(i) +
                                                "]: " + std::to_string(r) +
                                                " (radii must be finite and >= 0)"};
  }
  return {};
}

// This process's rank among the ranks of comm on the same node (spreads ranks over GPUs).
int node_local_rank(MPI_Comm comm) {
  MPI_Comm node = MPI_COMM_NULL;
  int rank = 0;
  if (MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node) != MPI_SUCCESS)
    return 0;
  MPI_Comm_rank(node, &rank);
  MPI_Comm_free(&node);
  return rank;
}

// When this process started (from /proc), or 0 where unknown: an output's temporary file
// modified before it was left by an earlier run.
std::time_t process_start_time() {
  std::ifstream self("/proc/self/stat"), system("/proc/stat");
  std::string line;
  if (!std::getline(self, line)) return 0;
  const size_t comm_end = line.rfind(')');  // the command name may hold spaces
  if (comm_end == std::string::npos) return 0;
  std::istringstream fields(line.substr(comm_end + 1));
  std::string field;
  unsigned long long ticks = 0;
  for (int k = 3; k <= 22 && fields >> field; ++k)
    if (k == 22) ticks = std::strtoull(field.c_str(), nullptr, 10);
  for (std::string key; system >> key;)
    if (key == "btime") {
      long long boot = 0;
      system >> boot;
      return std::time_t(boot + ticks / std::max(1L, sysconf(_SC_CLK_TCK)));
    }
  return 0;
}

// The object-space ambient occlusion volumes of a step's scenes that take the refit's stream of
// positions (OcclusionVolume::arm_tap), one tap for the refit to call.
class OcclusionTaps : public PositionTap {
 public:
  bool empty() const { return volumes_.empty(); }
  void add(OcclusionVolume *v) { volumes_.push_back(v); }
  void begin(int parts) override {
    for (OcclusionVolume *v : volumes_) v->begin_tapped_parts(parts);
  }
  // On the refit's threads at once, each its own part: every volume keeps its parts apart.
  void take(int part, const double *xyz, int64_t first, int64_t end) override {
    for (OcclusionVolume *v : volumes_) v->take_tapped(part, xyz, first, end);
  }

 private:
  std::vector<OcclusionVolume *> volumes_;
};

// Arms the tap of every scene that draws spheres with object-space ambient occlusion (a budget
// may still choose otherwise for this step: its scene then drops the deposit).
OcclusionTaps arm_occlusion_taps(const std::vector<SceneConfig> &scenes,
                                 std::vector<SceneBuffers> *buffers) {
  OcclusionTaps taps;
  for (size_t s = 0; s < scenes.size() && s < buffers->size(); ++s) {
    const AmbientOcclusionConfig &ao = scenes[s].ambient_occlusion;
    OcclusionVolume &volume = (*buffers)[s].occlusion;
    if (ao.enabled && ao.method == AmbientOcclusionMethod::kObject &&
        scenes[s].style != SceneStyle::kDensity && volume.arm_tap())
      taps.add(&volume);
  }
  return taps;
}

}  // namespace

void Runtime::remove_stale_temporaries_of_outputs() const {
  if (rank_ != 0) return;
  const std::time_t started = process_start_time();
  if (started == 0) return;
  std::set<std::string> directories;
  for (const SceneConfig &scene : config_.scenes) {
    const std::string &pattern = scene.output.pattern;
    const size_t slash = pattern.rfind('/');
    const std::string folder = slash == std::string::npos ? "" : pattern.substr(0, slash);
    if (folder.find("{step") != std::string::npos) continue;  // a folder per step: not scanned
    directories.insert(expand_pattern(folder, 0, scene.name));
  }
  for (const std::string &directory : directories) {
    const std::vector<std::string> removed = remove_stale_temporaries(directory, started);
    if (!removed.empty())
      std::fprintf(stderr,
                   "lantern: removed %zu temporary file(s) an earlier run left in '%s' (e.g. "
                   "'%s')\n",
                   removed.size(), directory.empty() ? "." : directory.c_str(),
                   removed.front().c_str());
  }
}

Status Runtime::open_gl() {
  gl_tried_ = true;
  const EglOptions egl{config_.egl_device, node_local_rank(comm_)};
  std::string passed_over;
  const Status local = GlSession::acquire(config_.gl, egl, &gl_, &passed_over);
  if (Status s = agree_on_status(comm_, local); !s.ok()) return s;
  // Every rank draws with OpenGL or none does: the two renderers may differ in a pixel's last
  // bit, and an image must not depend on which rank drew what.
  int have = gl_ ? 1 : 0, all = 0;
  MPI_Allreduce(&have, &all, 1, MPI_INT, MPI_MIN, comm_);
  if (!all) gl_.reset();
  const std::string why = config_.gl == GlBackend::kNone
                              ? std::string("gl: none (or LANTERN_GL=none)")
                          : have ? std::string("a rank has no OpenGL")
                                 : "no OpenGL back end works here: " + passed_over;
  for (const SceneConfig &scene : config_.scenes)
    if (scene.renderer == RendererChoice::kOpenGl && !gl_)
      return {StatusCode::kConfig, "scenes '" + scene.name + "': renderer: opengl, but " + why +
                                       " (use renderer: cpu or auto)"};
  if (rank_ != 0) return {};
  std::string not_cpu;  // scenes that may resolve to OpenGL (renderer auto)
  for (const SceneConfig &scene : config_.scenes)
    if (scene.renderer != RendererChoice::kCpu)
      not_cpu += (not_cpu.empty() ? "'" : ", '") + scene.name + "'";
  if (!gl_ && !not_cpu.empty())
    std::fprintf(stderr, "lantern: warning: %s; scenes %s are drawn by the CPU raster\n",
                 why.c_str(), not_cpu.c_str());
  else if (gl_ && !passed_over.empty())
    std::fprintf(stderr, "lantern: warning: OpenGL through %s (passed over: %s)\n", gl_->backend(),
                 passed_over.c_str());
  return {};
}

Status Runtime::open(const std::string &config_text, MPI_Comm comm, std::unique_ptr<Runtime> *out,
                     const Status &caller) {
  std::unique_ptr<Runtime> rt(new Runtime());
  if (MPI_Comm_dup(comm, &rt->comm_) != MPI_SUCCESS)
    return {StatusCode::kMpi, "mpi_comm_f: MPI_Comm_dup failed on this communicator"};
  MPI_Comm_rank(rt->comm_, &rt->rank_);
  MPI_Comm_size(rt->comm_, &rt->size_);

  Status local = caller.ok() ? rt->load_first_config(config_text) : caller;
  if (local.ok()) local = check_scene_movies(rt->config_.scenes);
  if (local.ok()) local = check_scene_overlays(rt->config_.scenes);
  if (Status s = agree_on_status(rt->comm_, local); !s.ok()) return s;
  if (Status s = rt->agree_on_first_config(); !s.ok()) return s;
  const MemoryShare share = node_memory_share(rt->comm_);  // collective
  if (Status s =
          agree_on_status(rt->comm_, check_scene_memory(estimate_scene_memory(rt->config_), share));
      !s.ok())
    return s;
  if (!rt->config_.scenes.empty())
    if (Status s = rt->open_gl(); !s.ok()) return s;
  rt->buffers_.resize(rt->config_.scenes.size());
  rt->warn_about_scenes();
  rt->remove_stale_temporaries_of_outputs();
  if (rt->config_.dump.enabled) {
    rt->dump_ = std::make_unique<DumpStage>(rt->config_.dump);
    if (Status s = rt->dump_->check_existing_file(rt->comm_); !s.ok()) return s;
  }
  // Movie files are opened now (after the checks that may refuse the open, so a refused open
  // leaves no movie file), so an unwritable path fails here rather than at the first frame.
  if (Status s = open_scene_movies(rt->comm_, rt->config_.scenes, &rt->buffers_); !s.ok()) return s;
  *out = std::move(rt);
  return {};
}

Runtime::~Runtime() {
  // Close the dump file (collective) while the communicator is valid; after MPI_Finalize it
  // can no longer be closed, and leaking it beats crashing in HDF5.
  int mpi_finalized = 0;
  MPI_Finalized(&mpi_finalized);
  if (mpi_finalized) static_cast<void>(dump_.release());
  dump_.reset();
  if (comm_ != MPI_COMM_NULL) {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Comm_free(&comm_);
  }
}

Status Runtime::publish(const ParticleDescription &particles) {
  ParticleArrays validated;
  particles_ =
      ParticleArrays();   // a failed publish leaves no particles (lantern_publish in the C API)
  bonds_ = BondArrays();  // their indices referred to the arrays being replaced
  ++bonds_serial_;
  bonds_given_ = false;
  if (Status s = ParticleArrays::validate(particles, &validated); !s.ok()) return s;
  if (Status s = check_radii(validated); !s.ok()) return s;
  particles_ = validated;
  return {};
}

Status Runtime::publish_bonds(const BondDescription &bonds) {
  BondArrays validated;
  bonds_ = BondArrays();  // a failed publish leaves no bonds (lantern_publish_bonds)
  ++bonds_serial_;
  if (Status s = BondArrays::validate(bonds, particles_, &validated); !s.ok()) return s;
  if (Status s = check_bonds(validated, particles_); !s.ok()) return s;
  bonds_ = validated;
  bonds_given_ = true;
  return {};
}

Status Runtime::mpi_usable(const char *function) const {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) return {};
  return {StatusCode::kMpi,
          std::string(function) +
              ": MPI was finalized (MPI_Finalize) while this context was open; close Lantern "
              "contexts before MPI_Finalize (mpi4py finalizes MPI at exit, after them)"};
}

Status Runtime::finish() {
  Status local;
  for (size_t s = 0; s < buffers_.size(); ++s)
    if (Status st = buffers_[s].writer.wait(); !st.ok() && local.ok())
      local = with_context("scenes '" + config_.scenes[s].name + "': ", std::move(st));
  // Rank 0's movies are completed before anything collective, so that they are whole even
  // after the host's MPI_Finalize.
  const Status movies = finish_movies_on_this_rank(config_.scenes, &buffers_);
  // After MPI_Finalize nothing collective can run: this rank's images and movies were waited
  // for, the context is released without the others (the destructor leaves the dump file to
  // HDF5, which closed it in MPI_Finalize).
  if (Status s = mpi_usable("lantern_close"); !s.ok()) {
    const Status &first = local.ok() ? movies : local;
    return first.ok() ? s : Status(s.code, s.message + "; and " + first.message);
  }
  const Status images = broadcast_status(comm_, local, 0);
  const Status movies_everywhere = broadcast_status(comm_, movies, 0);
  return images.ok() ? movies_everywhere : images;
}

void Runtime::warn_about_scenes() const {
  if (rank_ != 0) return;
  for (const SceneConfig &scene : config_.scenes)
    if (scene.style == SceneStyle::kDensity)
      if (const std::string problem = density_range_problem(scene.density); !problem.empty())
        std::fprintf(stderr, "lantern: warning: scenes '%s': %s\n", scene.name.c_str(),
                     problem.c_str());
}

void Runtime::warn_nonfinite_once(int64_t count, int64_t step) {
  if (count == 0 || warned_nonfinite_) return;
  warned_nonfinite_ = true;
  if (rank_ == 0)
    std::fprintf(stderr,
                 "lantern: warning: step %lld: %lld particles with NaN or infinite coordinates "
                 "skipped (counted in the stats as nonfinite; warned once)\n",
                 static_cast<long long>(step), static_cast<long long>(count));
}

// A scene with a `bonds:` section on a run that never hands bonds over draws none: said once (on
// the first rendered step with such a scene), so that a missing lantern_publish_bonds - or a
// client started without bonds, as lantern-lammps is when no scene drew them at its start - is
// not silent. A step with zero bonds published is not this case. Collective (one reduction).
void Runtime::warn_if_no_bonds_given(int64_t step) {
  bonds_checked_ = true;
  int given = bonds_given_ ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &given, 1, MPI_INT, MPI_MAX, comm_);
  if (given || rank_ != 0) return;
  std::fprintf(stderr,
               "lantern: warning: step %lld: scenes have a bonds: section, but no rank published "
               "bonds (lantern_publish_bonds after lantern_publish): no bonds are drawn (warned "
               "once)\n",
               static_cast<long long>(step));
}

Status Runtime::set_box(const Box &box) {
  if (Status s = validate_box(box); !s.ok()) return with_context("box: ", std::move(s));
  box_ = box;
  PeriodicBox periodic;
  for (int a = 0; a < 3; ++a) {
    periodic.length[a] = box.high[a] - box.low[a];
    periodic.periodic[a] = box.periodic[a];
  }
  if (box.triclinic) periodic.tilt = box.tilt;
  periodic_box_ = periodic;
  return {};
}

Status Runtime::execute(int64_t step, double time) {
  bool dump_due = dump_ && dump_->due(step);
  bool render_due = config_.schedule.due(step);
  if (!dump_due && !render_due) return {};
  if (Status s = mpi_usable("lantern_execute"); !s.ok()) return s;
  if (watch_.active() && follow_config_file(step)) {  // the edited file rules from this step on
    dump_due = dump_ && dump_->due(step);
    render_due = config_.schedule.due(step);
    if (!dump_due && !render_due) return {};
  }
  // One scan and one reduction per step, for the dump and every scene. On a later step whose
  // bricks refit, their bounds give the scan's result and the pass is left out (a dump step
  // scans: it writes before the scenes run).
  const auto t_scan = Clock::now();
  // budget_percent: the wall time the simulation had since the last rendered step returned.
  const double gap_ms =
      render_due && last_render_end_
          ? std::chrono::duration<double, std::milli>(t_scan - *last_render_end_).count()
          : 0.0;
  const int threads = config_.threads > 0 ? config_.threads : default_thread_count();
  BrickOptions refit_options;
  refit_options.threads = threads;
  // Scenes with object-space ambient occlusion deposit the positions as the refit streams them.
  // (Armed on every rendered step: arming drops what an earlier step's tap left.)
  OcclusionTaps taps;
  if (render_due) taps = arm_occlusion_taps(config_.scenes, &buffers_);
  if (!taps.empty()) refit_options.tap = &taps;
  Extent local;
  scratch_.bricks.begin_call();
  const bool from_bricks = render_due && !dump_due && !config_.scenes.empty() &&
                           scratch_.bricks.refit_first(particles_, step, refit_options) &&
                           extent_of_bricks(scratch_.bricks.bricks(), particles_, &local);
  if (!from_bricks) local = scan_particles(particles_, particles_.has_radius(), 0.0, threads);
  const Extent global = reduce_extent(comm_, local);
  const double scan_ms = ms_since(t_scan);
  // The dump has its own schedule; a dump error is returned unless rendering fails too.
  const Status dumped =
      dump_due ? dump_->write(comm_, particles_, bonds_, global, box_, step, time) : Status();
  if (!render_due) return dumped;
  const auto t0 = Clock::now();
  warn_nonfinite_once(global.nonfinite_count, step);

  Status first_error;
  std::vector<SceneStats> stats(config_.scenes.size());
  if (!config_.scenes.empty()) {
    SphereRenderer *renderer = nullptr;  // none without OpenGL: the CPU raster draws
    const Status made_current = gl_ ? gl_->renderer(&renderer) : Status();
    first_error = agree_on_status(comm_, made_current);
    if (!first_error.ok()) stats.clear();  // no scene was drawn
    ScenePassInputs in{comm_, renderer, &particles_, global, step, time, &scratch_};
    in.bonds = &bonds_;
    in.bonds_serial = bonds_serial_;
    in.periodic_box = periodic_box_ ? &*periodic_box_ : nullptr;
    in.per_rank_stats = !config_.stats_file.empty();  // the same configuration on every rank
    in.threads = threads;
    in.local = &local;
    in.box = box_ ? &*box_ : nullptr;
    if (!config_.lammps.scalar.empty()) in.scalar_name = config_.lammps.scalar;
    const bool budgeted = config_.budget_percent.has_value() ||
                          std::any_of(config_.scenes.begin(), config_.scenes.end(),
                                      [](const SceneConfig &c) { return c.budget_ms.has_value(); });
    std::vector<bool> rendered(stats.size(), false);
    for (size_t s = 0; s < stats.size(); ++s) {
      const SceneConfig &configured = config_.scenes[s];
      // A budgeted scene draws with the settings its controller chose from earlier steps.
      std::optional<SceneConfig> chosen;
      if (configured.budget_ms || config_.budget_percent) {
        stats[s].budget.emplace();
        chosen = buffers_[s].budget.choose(configured, scene_budget_ms(s), &*stats[s].budget);
      }
      const Status st = run_scene_pass(in, chosen ? *chosen : configured, &buffers_[s], &stats[s]);
      rendered[s] = st.ok();                               // agreed: the same on every rank
      if (!st.ok() && first_error.ok()) first_error = st;  // later scenes still render
    }
    if (budgeted && !stats.empty()) record_scene_costs(gap_ms, rendered, &stats);
    // Bonds that went bad since they were published were left out of the images; say which.
    // Collective where some scene draws bonds (the same configuration on every rank).
    const bool any_bonds = std::any_of(config_.scenes.begin(), config_.scenes.end(),
                                       [](const SceneConfig &c) { return c.bonds.enabled; });
    if (any_bonds) {
      const Status bonds = agree_on_status(comm_, scratch_.bonds.status(step));
      if (!bonds.ok() && first_error.ok()) first_error = bonds;
      if (!bonds_checked_) warn_if_no_bonds_given(step);
    }
  }
  const double total_ms = scan_ms + ms_since(t0);
  // What this call returns, and so what the step's stats line reports: the first scene's error,
  // else the dump's.
  const Status result = first_error.ok() ? dumped : first_error;
  const Status stats_written = write_stats(step, time, global, total_ms, stats, result);
  if (config_.verbose && rank_ == 0) {
    std::string budgets;
    for (const SceneStats &sc : stats)
      if (sc.budget) {
        const BudgetStats &b = *sc.budget;
        char error[32] = "exact";
        if (b.rung > 0) std::snprintf(error, sizeof error, "~%.1f dB", b.psnr_db);
        char text[256];
        std::snprintf(text, sizeof text,
                      "; '%s': budget %.1f ms, rung %d/%d (lod %g, samples %d, ao %s), %.1f ms, "
                      "%s%s",
                      sc.name.c_str(), b.budget_ms, b.rung, b.rungs - 1, b.lod_fraction, b.samples,
                      b.ambient_occlusion.c_str(), b.measured_ms, error,
                      b.unmet ? ", over budget" : "");
        budgets += text;
      }
    std::fprintf(stderr, "lantern: step %lld rendered %zu scene(s) in %.1f ms%s\n",
                 static_cast<long long>(step), stats.size(), total_ms, budgets.c_str());
  }
  last_render_end_ = Clock::now();
  if (result.ok()) return stats_written;
  // The step failed anyway; say that its stats were lost too.
  if (!stats_written.ok() && rank_ == 0)
    std::fprintf(stderr, "lantern: warning: step %lld: %s\n", static_cast<long long>(step),
                 stats_written.message.c_str());
  return result;
}

double Runtime::scene_budget_ms(size_t s) const {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double budget = config_.scenes[s].budget_ms.value_or(nan);
  if (!config_.budget_percent || !(render_gap_ms_ > 0.0)) return budget;
  // The run-wide budget, shared in proportion to the scenes' predicted full-quality costs, so
  // that every scene gives up alike; unknown until every scene was measured once.
  double all = 0.0;
  for (const SceneBuffers &b : buffers_) all += b.budget.controller.predicted_ms(0);
  const double share = *config_.budget_percent / 100.0 * render_gap_ms_ *
                       buffers_[s].budget.controller.predicted_ms(0) / all;
  if (!(share > 0.0)) return budget;  // NaN: a scene not measured yet
  return std::isnan(budget) ? share : std::min(budget, share);
}

void Runtime::record_scene_costs(double gap_ms, const std::vector<bool> &rendered,
                                 std::vector<SceneStats> *stats) {
  // One reduction: the gap before this step and every scene's cost, the slowest rank's.
  std::vector<double> local(1 + stats->size(), 0.0), slowest(local.size(), 0.0);
  local[0] = std::isfinite(gap_ms) ? gap_ms : 0.0;
  for (size_t s = 0; s < stats->size(); ++s)
    local[1 + s] = rendered[s] && std::isfinite((*stats)[s].total_ms) ? (*stats)[s].total_ms : 0.0;
  MPI_Allreduce(local.data(), slowest.data(), int(local.size()), MPI_DOUBLE, MPI_MAX, comm_);
  if (slowest[0] > 0.0) render_gap_ms_ = slowest[0];
  for (size_t s = 0; s < stats->size(); ++s) {
    if (!(*stats)[s].budget) continue;
    BudgetStats &b = *(*stats)[s].budget;
    SceneBudget &budget = buffers_[s].budget;
    b.measured_ms = slowest[1 + s];
    budget.controller.record(b.rung, b.measured_ms);  // ignores 0: a scene that failed
    if (b.unmet && !budget.warned_unmet) {            // the same on every rank
      budget.warned_unmet = true;
      b.note = "budget cannot be met: rendering at the cheapest setting";
      if (rank_ == 0)
        std::fprintf(stderr,
                     "lantern: warning: scenes '%s': budget %.1f ms cannot be met: rendering at "
                     "the cheapest setting (lod %g, samples %d, ambient occlusion %s), predicted "
                     "%.1f ms (the stats say \"unmet\"; warned once)\n",
                     config_.scenes[s].name.c_str(), b.budget_ms, b.lod_fraction, b.samples,
                     b.ambient_occlusion.c_str(), b.predicted_ms);
    }
  }
}

Status Runtime::write_stats(int64_t step, double time, const Extent &global, double total_ms,
                            const std::vector<SceneStats> &scenes, const Status &status) {
  if (config_.stats_file.empty()) return {};
  Status local;
  if (rank_ == 0) {
    nlohmann::json line = {
        {"step", step},
        {"time", time},
        {"ranks", size_},
        {"gl", gl_ ? gl_->backend() : "none"},
        {"status", int(status.code)},
        {"particles", {{"finite", global.finite_count}, {"nonfinite", global.nonfinite_count}}},
        {"ms", {{"total", total_ms}}},
        {"scenes", nlohmann::json::array()}};
    for (const auto &s : scenes) line["scenes"].push_back(s.to_json());
    if (!config_event_.empty()) line["config"] = std::exchange(config_event_, std::string());
    load_summary_ = "step " + std::to_string(step) + ", " + std::to_string(size_) + " ranks:\n";
    for (const auto &s : scenes)
      if (s.per_rank) load_summary_ += "  " + s.per_rank_line() + "\n";
    local = with_context("stats: ", append_json_line(config_.stats_file, line));
  }
  // Only rank 0 writes; every rank returns its outcome, so that all return the same status.
  return broadcast_status(comm_, local, 0);
}

}  // namespace lantern
