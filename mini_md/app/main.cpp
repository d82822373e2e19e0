// mini_md: a Lennard-Jones molecular dynamics code with MPI domain decomposition that can drive
// Lantern in situ. All physics lives in mini_md_lib; this file parses the command line, wires
// the optional renderer and prints the summary.
#include <lantern/lantern.h>
#include <mpi.h>

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include "cli.h"
#include "dt_sweep.h"
#include "lantern_bridge.h"
#include "md_error.h"
#include "simulation.h"

namespace {

using namespace mini_md;

// The loop time `seconds` and its breakdown (force + neighbor + comm + insitu + other).
struct LoopTimes {
  double seconds = 0.0, force = 0.0, neighbor = 0.0, comm = 0.0, insitu = 0.0, other = 0.0;
};

// The keys up to insitu_seconds are parsed by scripts: append new keys, never reorder.
void print_perf(int64_t atoms, int ranks, int64_t steps, const LoopTimes &t) {
  const double rate = t.seconds > 0 ? static_cast<double>(atoms) * steps / t.seconds : 0.0;
  std::printf(
      "PERF atoms=%lld ranks=%d steps=%lld seconds=%.6f atom_steps_per_s=%.6e "
      "insitu_seconds=%.6f force_seconds=%.6f neighbor_seconds=%.6f comm_seconds=%.6f "
      "other_seconds=%.6f\n",
      static_cast<long long>(atoms), ranks, static_cast<long long>(steps), t.seconds, rate,
      t.insitu, t.force, t.neighbor, t.comm, t.other);
}

int run_simulation(const CommandLine &cl, MPI_Comm comm, int rank, int size) {
  Simulation sim(cl.run, comm);
  std::unique_ptr<LanternBridge> bridge;
  if (!cl.run.render_config.empty()) {
    const double t0 = MPI_Wtime();
    bridge = std::make_unique<LanternBridge>(cl.run.render_config, comm);
    bridge->set_box(sim.scene().box);
    sim.set_observer(bridge.get());
    if (rank == 0) std::printf("mini_md: Lantern opened in %.3f s\n", MPI_Wtime() - t0);
  }
  sim.setup();
  sim.run(cl.run.steps);
  const RunCounters &c = sim.counters();
  if (rank == 0) {
    std::printf(
        "mini_md: setup %.3f s, loop %.3f s, %lld neighbour builds, %lld atoms "
        "migrated (rank 0), at most %d hop(s) per axis\n",
        c.setup_seconds, c.loop_seconds, static_cast<long long>(c.rebuilds),
        static_cast<long long>(c.migrated), c.max_hops);
    // The loop time is what LAMMPS reports as "Loop time"; it includes in-situ time.
    print_perf(sim.natoms(), size, cl.run.steps,
               {c.loop_seconds, c.force_seconds, c.neighbor_seconds, c.comm_seconds,
                c.insitu_seconds, c.other_seconds()});
    if (const std::string load = bridge ? bridge->load_summary() : ""; !load.empty())
      std::printf("mini_md: Lantern's per-rank load, %s", load.c_str());
  }
  return 0;
}

// `text` into `path` whole or not at all: written under a temporary name beside it, checked, then
// renamed over it (a full disk or an unwritable folder leaves any earlier file as it was).
// Returns "" or why not.
std::string write_whole_file(const std::string &path, const std::string &text) {
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
  if (!out) return std::strerror(errno);
  out << text;
  out.close();
  if (!out) {
    std::remove(temporary.c_str());
    return "the file could not be written";
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    std::remove(temporary.c_str());
    return why;
  }
  return {};
}

int run_sweep(const CommandLine &cl, MPI_Comm comm, int rank, int size) {
  const double t0 = MPI_Wtime();
  const std::vector<SweepRow> rows = run_dt_sweep(cl.run, cl.sweep_dts, cl.sweep_time, comm);
  if (rank != 0) return 0;
  std::printf("%s\n%s", format_sweep_table(rows, cl.sweep_time).c_str(),
              format_sweep_csv(rows).c_str());
  if (!cl.csv_path.empty()) {
    if (const std::string why = write_whole_file(cl.csv_path, format_sweep_csv(rows));
        !why.empty()) {
      std::fprintf(stderr, "mini_md: error: --csv %s: cannot write the file: %s\n",
                   cl.csv_path.c_str(), why.c_str());
      return 1;
    }
  }
  int64_t steps = 0;
  for (const SweepRow &r : rows) steps += r.steps;
  // The sweep's several runs are not broken down: all of the time is "other".
  const double seconds = MPI_Wtime() - t0;
  print_perf(rows.empty() ? 0 : rows.front().atoms, size, steps, {seconds, 0, 0, 0, 0, seconds});
  return 0;
}

}  // namespace

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int code = 0;
  try {
    const CommandLine cl = parse_command_line(argc, argv);
    if (cl.help) {
      if (rank == 0) std::printf("%s", usage_text().c_str());
    } else if (cl.version) {
      // mini_md is versioned with the Lantern it is built in; the library it runs against says.
      if (rank == 0) std::printf("mini_md (Lantern) %s\n", lantern_version());
    } else if (cl.dt_sweep) {
      code = run_sweep(cl, MPI_COMM_WORLD, rank, size);
    } else {
      code = run_simulation(cl, MPI_COMM_WORLD, rank, size);
    }
  } catch (const MdError &e) {
    // MdErrors are raised on every rank together, so all ranks reach this point.
    std::fflush(stdout);
    if (rank == 0) std::fprintf(stderr, "mini_md: error: %s\n", e.what());
    code = 2;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "mini_md: rank %d: fatal: %s\n", rank, e.what());
    MPI_Abort(MPI_COMM_WORLD, 3);
  }
  MPI_Finalize();
  return code;
}
