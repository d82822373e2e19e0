#include "dt_sweep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "md_error.h"
#include "simulation.h"

namespace mini_md {

std::vector<SweepRow> run_dt_sweep(const RunConfig &base, const std::vector<double> &dts,
                                   double sim_time, MPI_Comm comm) {
  std::vector<SweepRow> rows;
  for (const double dt : dts) {
    RunConfig cfg = base;
    cfg.dt = dt;
    cfg.langevin_temp.reset();
    cfg.print_thermo = false;
    cfg.steps = std::max<int64_t>(1, std::llround(sim_time / dt));
    cfg.thermo_every = std::max<int64_t>(1, cfg.steps / 200);
    SweepRow row;
    row.dt = dt;
    row.steps = cfg.steps;
    Simulation sim(cfg, comm);
    row.atoms = sim.natoms();
    try {
      sim.setup();
      sim.run(cfg.steps);
    } catch (const MdError &e) {  // collective: every rank catches the same error
      row.stable = false;
      row.note = e.what();
    }
    const auto &log = sim.thermo_log();
    if (log.empty()) {
      rows.push_back(row);
      continue;
    }
    const double e0 = log.front().e_conserved_atom;
    row.drift_atom = log.back().e_conserved_atom - e0;
    for (const ThermoState &t : log) {
      row.max_dev_atom = std::max(row.max_dev_atom, std::fabs(t.e_conserved_atom - e0));
    }
    row.seconds = sim.counters().loop_seconds;
    rows.push_back(row);
  }
  return rows;
}

std::string format_sweep_table(const std::vector<SweepRow> &rows, double sim_time) {
  std::ostringstream out;
  char line[200];
  std::snprintf(line, sizeof line,
                "dt sweep: NVE over %g time units; E/atom with U shifted to 0 at the cutoff\n",
                sim_time);
  out << line;
  std::snprintf(line, sizeof line, "%8s %8s %16s %16s %10s  %s\n", "dt", "steps", "drift E/atom",
                "max|dE|/atom", "wall [s]", "status");
  out << line;
  for (const SweepRow &r : rows) {
    std::snprintf(line, sizeof line, "%8g %8lld %16.3e %16.3e %10.3f  %s\n", r.dt,
                  static_cast<long long>(r.steps), r.drift_atom, r.max_dev_atom, r.seconds,
                  r.stable ? "ok" : "BLEW UP");
    out << line;
  }
  for (const SweepRow &r : rows) {
    if (!r.stable) out << "  dt " << r.dt << ": " << r.note << "\n";
  }
  return out.str();
}

std::string format_sweep_csv(const std::vector<SweepRow> &rows) {
  std::ostringstream out;
  out << "dt,steps,drift_e_per_atom,max_abs_de_per_atom,wall_seconds,stable\n";
  char line[200];
  for (const SweepRow &r : rows) {
    std::snprintf(line, sizeof line, "%g,%lld,%.6e,%.6e,%.6f,%d\n", r.dt,
                  static_cast<long long>(r.steps), r.drift_atom, r.max_dev_atom, r.seconds,
                  r.stable ? 1 : 0);
    out << line;
  }
  return out.str();
}

}  // namespace mini_md
