// Stiff and extreme cases on one rank: each ends in the documented error or, with --relax, in a
// finite state.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <string>

#include "cli.h"
#include "md_error.h"
#include "simulation.h"

namespace mini_md {
namespace {

RunConfig random_start(int cells) {
  RunConfig cfg;
  cfg.scene = SceneKind::kRandom;
  cfg.cells = cells;
  cfg.print_thermo = false;
  cfg.thermo_every = 10;
  return cfg;
}

// Runs setup + steps and returns the MdError message ("" if none was thrown).
std::string run_expecting_error(const RunConfig &cfg, int64_t steps) {
  try {
    Simulation sim(cfg, MPI_COMM_SELF);
    sim.setup();
    sim.run(steps);
  } catch (const MdError &e) {
    return e.what();
  }
  return "";
}

bool all_finite(const Atoms &a) {
  for (int i = 0; i < a.nlocal; ++i) {
    for (int d = 0; d < 3; ++d) {
      if (!std::isfinite(a.x[i][d]) || !std::isfinite(a.v[i][d]) || !std::isfinite(a.f[i][d])) {
        return false;
      }
    }
  }
  return true;
}

// Random placement at liquid density: overlapping atoms. Without --relax the run must stop
// with a message naming the step, an atom and the remedies.
TEST(MiniMdStiff, RandomStartWithoutRelaxStopsWithRemedy) {
  const std::string msg = run_expecting_error(random_start(5), 100);
  ASSERT_FALSE(msg.empty()) << "an overlapping random start ran silently";
  EXPECT_NE(msg.find("step "), std::string::npos) << msg;
  EXPECT_NE(msg.find("atom "), std::string::npos) << msg;
  EXPECT_NE(msg.find("--dt"), std::string::npos) << msg;
  EXPECT_NE(msg.find("--relax"), std::string::npos) << msg;
}

// The same start with --relax: finite, sensible, and it stays finite for 200 NVE steps.
TEST(MiniMdStiff, RandomStartWithRelaxIsFinite) {
  RunConfig cfg = random_start(5);
  cfg.relax = true;
  Simulation sim(cfg, MPI_COMM_SELF);
  sim.setup();
  EXPECT_TRUE(all_finite(sim.atoms()));
  EXPECT_LT(sim.thermo_log().front().pe_atom, 0.0);  // relaxed: attractive, no overlaps
  sim.run(200);
  EXPECT_TRUE(all_finite(sim.atoms()));
  EXPECT_TRUE(std::isfinite(sim.thermo_log().back().etot_atom));
}

// Two atoms at exactly the same place: no direction exists for their repulsion; --relax still
// separates them (along an id-derived direction) without producing NaN.
TEST(MiniMdStiff, CoincidentAtomsRelaxToFiniteState) {
  RunConfig cfg;
  cfg.cells = 4;
  cfg.print_thermo = false;
  cfg.relax = true;
  Simulation sim(cfg, MPI_COMM_SELF);
  sim.atoms().x[1] = sim.atoms().x[0];
  sim.atoms().x[2] = sim.atoms().x[0];
  sim.setup();
  EXPECT_TRUE(all_finite(sim.atoms()));
  sim.run(50);
  EXPECT_TRUE(all_finite(sim.atoms()));
}

// A time step far too large for LJ: the run stops, naming a step, an atom and --dt.
TEST(MiniMdStiff, HugeTimeStepStops) {
  RunConfig cfg;
  cfg.cells = 4;
  cfg.print_thermo = false;
  cfg.dt = 0.1;
  const std::string msg = run_expecting_error(cfg, 200);
  ASSERT_FALSE(msg.empty());
  EXPECT_NE(msg.find("--dt"), std::string::npos) << msg;
  EXPECT_NE(msg.find("atom "), std::string::npos) << msg;
}

// A box too small for any subdomain to hold the ghost layer is rejected up front.
TEST(MiniMdStiff, BoxSmallerThanCutoffRejected) {
  RunConfig cfg;
  cfg.cells = 1;  // L = 1.68 < cutoff + skin
  cfg.print_thermo = false;
  const std::string msg = run_expecting_error(cfg, 1);
  EXPECT_NE(msg.find("cannot decompose"), std::string::npos) << msg;
}

TEST(MiniMdCli, ParsesOptionsAndRejectsUnknown) {
  const char *argv[] = {"mini_md", "--scene",  "void_impact",   "--cells", "7",
                        "--dt",    "0.002",    "--neigh-check", "no",      "--langevin",
                        "0.5",     "--render", "a.yaml"};
  const CommandLine cl = parse_command_line(13, argv);
  EXPECT_EQ(cl.run.scene, SceneKind::kVoidImpact);
  EXPECT_EQ(cl.run.cells, 7);
  EXPECT_DOUBLE_EQ(cl.run.dt, 0.002);
  EXPECT_FALSE(cl.run.neigh_check);
  EXPECT_DOUBLE_EQ(*cl.run.langevin_temp, 0.5);
  EXPECT_EQ(cl.run.render_config, "a.yaml");
  const char *bad[] = {"mini_md", "--cellz", "7"};
  EXPECT_THROW(parse_command_line(3, bad), MdError);
  const char *bad_value[] = {"mini_md", "--cells", "seven"};
  EXPECT_THROW(parse_command_line(3, bad_value), MdError);
}

}  // namespace
}  // namespace mini_md
