// The runaway warning: silent for physical states, once per kind for states that left every
// physical range, whatever stop criteria the user switched off.
#include <gtest/gtest.h>

#include <limits>

#include "runaway_watch.h"

namespace mini_md {
namespace {

// Step 0 of in.lj (LAMMPS bench): T 1.44, PE/atom -6.77, E/atom -4.61.
ThermoState in_lj_start() {
  ThermoState t;
  t.temperature = 1.44;
  t.pe_atom = -6.7733681;
  t.ke_atom = 2.1599325;
  t.etot_atom = -4.6134356;
  return t;
}

ThermoState state(int64_t step, double temperature, double etot_atom) {
  ThermoState t;
  t.step = step;
  t.temperature = temperature;
  t.etot_atom = etot_atom;
  return t;
}

TEST(MiniMdRunawayWatch, LimitsFollowTheInitialState) {
  const RunawayWatch watch(in_lj_start(), 1.44);
  EXPECT_DOUBLE_EQ(watch.temperature_limit(), 1440.0);  // 1e3 x 1.44
  EXPECT_DOUBLE_EQ(watch.energy_limit(), 6773.3681);    // 1e3 x |PE0/atom|
  // A cold start (void_impact, T 0.05) still allows T up to 1000: T_ref is at least 1.
  ThermoState cold = in_lj_start();
  cold.temperature = 0.05;
  EXPECT_DOUBLE_EQ(RunawayWatch(cold, 0.05).temperature_limit(), 1000.0);
  // A thermostat target above the start raises the scale.
  EXPECT_DOUBLE_EQ(RunawayWatch(in_lj_start(), 5.0).temperature_limit(), 5000.0);
}

TEST(MiniMdRunawayWatch, PhysicalStatesGiveNoWarning) {
  RunawayWatch watch(in_lj_start(), 1.44);
  // Hot, cold, melted, exploded to a gas: all physical.
  for (const double t : {0.0, 0.7, 3.0, 50.0, 1400.0}) {
    EXPECT_TRUE(watch.check(state(100, t, -4.6 + 1.5 * t)).empty()) << t;
  }
}

TEST(MiniMdRunawayWatch, RunawayWarnsOncePerKind) {
  RunawayWatch watch(in_lj_start(), 1.44);
  // The reported case: T = 2.35e19 after --neigh-check no --blowup-energy 1e308.
  const std::vector<std::string> first = watch.check(state(100, 2.35e19, 3.5e19));
  ASSERT_EQ(first.size(), 2u);
  EXPECT_NE(first[0].find("step 100: temperature 2.35e+19 is beyond 1440"), std::string::npos)
      << first[0];
  EXPECT_NE(first[1].find("step 100: energy per atom 3.5e+19 is beyond +-6773.37"),
            std::string::npos)
      << first[1];
  EXPECT_NE(first[0].find("--blowup-energy"), std::string::npos) << first[0];
  EXPECT_TRUE(watch.check(state(200, 1e20, 1e20)).empty());  // each kind once per run
}

TEST(MiniMdRunawayWatch, TemperatureAndEnergyWarnSeparately) {
  RunawayWatch watch(in_lj_start(), 1.44);
  const std::vector<std::string> energy_only = watch.check(state(10, 2.0, -1e5));
  ASSERT_EQ(energy_only.size(), 1u);
  EXPECT_NE(energy_only[0].find("energy per atom -100000"), std::string::npos) << energy_only[0];
  const std::vector<std::string> temperature_only = watch.check(state(20, 2000.0, -1e6));
  ASSERT_EQ(temperature_only.size(), 1u);
  EXPECT_NE(temperature_only[0].find("temperature 2000"), std::string::npos);
}

TEST(MiniMdRunawayWatch, NonFiniteWarns) {
  RunawayWatch watch(in_lj_start(), 1.44);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(watch.check(state(5, nan, std::numeric_limits<double>::infinity())).size(), 2u);
}

}  // namespace
}  // namespace mini_md
