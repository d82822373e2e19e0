// lantern-lammps: runs a LAMMPS input script and renders it in situ with Lantern.
//
//   mpiexec -n 4 lantern-lammps -in in.melt -lantern viz.yaml [LAMMPS options...]
//
// The script is LAMMPS's own, with one line added: `fix viz all external pf/callback 100
// 1000000000` (any fix ID and group; the second number, how often LAMMPS adds the fix's zero
// forces to the atoms', is best beyond the run). Every `pf/callback` fix external the script
// defines renders its group each time LAMMPS calls it (every 100 steps here; the YAML's
// `schedule:` can thin that further), or
// only the one named by the YAML's `lammps: {fix: ID}`. `lammps: {scalar: c_ke}` publishes a
// per-atom quantity as Lantern's scalar. Every other option goes to LAMMPS unchanged (-var,
// -log, -screen, -echo, -suffix, ...; LAMMPS's own -h lists its styles). --help and --version
// answer for lantern-lammps. Exit code: 0 (or N after the script's `quit N`, as lmp), 1 on any
// error (the message names the file and line, the fix, or the key at fault), 2 on a usage error.
#include <mpi.h>

#define LAMMPS_LIB_MPI 1
#include <lammps/library.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/config/config_loader.h"
#include "lammps_session.h"
#include "lantern/lantern.h"

namespace {

constexpr const char *kUsage =
    "usage: lantern-lammps -in SCRIPT -lantern CONFIG.yaml [LAMMPS options]\n"
    "       lantern-lammps --help | --version\n"
    "  SCRIPT: a LAMMPS input script with a `fix ID GROUP external pf/callback N M` line\n"
    "    (an image every N steps; M: how often LAMMPS adds the fix's zero forces, best\n"
    "    beyond the run, e.g. 1000000000);\n"
    "  every other option goes to LAMMPS (-var, -log, -screen, -suffix, ...; -h: LAMMPS's help)\n";

struct Arguments {
  bool help = false, version = false;  // --help, --version: answer and run nothing
  std::string input, config;
  std::vector<std::string> lammps{"lantern-lammps"};  // argv for lammps_open
  std::string error;                                  // a usage error, if any
};

Arguments parse(int argc, char **argv) {
  Arguments a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "--version") {
      (arg == "--help" ? a.help : a.version) = true;
      return a;
    }
    const bool ours = arg == "-in" || arg == "-i" || arg == "-lantern";
    if (!ours) {
      a.lammps.push_back(arg);
      continue;
    }
    if (i + 1 >= argc) {
      a.error = arg + " needs a file name";
      return a;
    }
    (arg == "-lantern" ? a.config : a.input) = argv[++i];
  }
  if (a.error.empty() && (a.input.empty() || a.config.empty()))
    a.error = "give the LAMMPS input script (-in FILE) and Lantern's configuration (-lantern FILE)";
  return a;
}

struct LammpsCloser {
  void operator()(void *lmp) const { lammps_close(lmp); }
};

// Seconds per lantern_execute() on the slowest rank (what LAMMPS waited): mean and median, on
// rank 0. Collective (the session made the same calls on every rank).
void print_timing(const std::vector<double> &local, int rank) {
  std::vector<double> slowest(local.size());
  MPI_Allreduce(local.data(), slowest.data(), int(local.size()), MPI_DOUBLE, MPI_MAX,
                MPI_COMM_WORLD);
  if (rank != 0) return;
  if (slowest.empty()) {
    std::fprintf(stderr, "lantern-lammps: 0 rendered steps\n");
    return;
  }
  double sum = 0;
  for (const double t : slowest) sum += t;
  std::sort(slowest.begin(), slowest.end());
  const size_t n = slowest.size();
  const double median = n % 2 ? slowest[n / 2] : 0.5 * (slowest[n / 2 - 1] + slowest[n / 2]);
  std::fprintf(stderr,
               "lantern-lammps: %zu rendered steps, seconds per step: mean %.4f median %.4f\n", n,
               sum / double(n), median);
}

int report(int rank, const std::string &message, int code) {
  if (rank == 0) std::fprintf(stderr, "lantern-lammps: error: %s\n", message.c_str());
  return code;
}

// Opens Lantern and LAMMPS, runs the script, closes both. Returns the exit code.
int run(const Arguments &args, int rank) {
  // The `lammps:` section of the configuration (Lantern validates the whole file as it opens).
  lantern_context *ctx = nullptr;
  if (lantern_open(args.config.c_str(), MPI_Comm_c2f(MPI_COMM_WORLD), &ctx) != LANTERN_OK) {
    const std::string message = lantern_error_message(ctx);
    lantern_close(ctx);
    return report(rank, args.config + ": " + message, 1);
  }
  lantern::Config config;
  static_cast<void>(lantern::load_config(args.config, &config));  // valid: lantern_open read it
  lantern_lammps::SessionOptions options{config.lammps.fix, config.lammps.scalar};
  for (const lantern::SceneConfig &scene : config.scenes) options.bonds |= scene.bonds.enabled;

  std::vector<char *> argv;
  std::vector<std::string> strings = args.lammps;
  for (std::string &s : strings) argv.push_back(s.data());
  std::unique_ptr<void, LammpsCloser> lmp(
      lammps_open(int(argv.size()), argv.data(), MPI_COMM_WORLD, nullptr));
  if (!lmp) {
    lantern_close(ctx);
    return report(rank, "lammps_open failed", 1);
  }
  int code = 0;
  try {
    lantern_lammps::Session session(lmp.get(), ctx, MPI_COMM_WORLD, options);
    try {
      session.run_script(args.input);
    } catch (const lantern_lammps::Failure &) {
      // Thrown out of a LAMMPS command: LAMMPS is mid-command and cannot be closed safely.
      if (session.inside_lammps()) static_cast<void>(lmp.release());
      throw;
    }
    print_timing(session.execute_seconds(), rank);
    code = session.quit_status().value_or(0);  // `quit N`: LAMMPS's exit status, as lmp's
  } catch (const lantern_lammps::Failure &e) {
    code = report(rank, e.what(), 1);
  }
  if (lantern_close(ctx) != LANTERN_OK && code == 0)
    code = report(rank, "closing Lantern's outputs failed", 1);
  return code;
}

}  // namespace

int main(int argc, char **argv) {
  const Arguments args = parse(argc, argv);
  // --help and --version answer on stdout without starting MPI or LAMMPS.
  if (args.help) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (args.version) {
    std::printf("lantern-lammps (Lantern) %s\n", lantern_version());
    return 0;
  }
  MPI_Init(&argc, &argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::string usage = kUsage;
  usage.pop_back();  // report() ends the line
  const int code =
      args.error.empty() ? run(args, rank) : report(rank, args.error + "\n" + usage, 2);
  MPI_Finalize();
  return code;
}
