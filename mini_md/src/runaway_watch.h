// Warnings for a run whose temperature or energy left every physical range by orders of
// magnitude although no stop criterion fired: with --neigh-check no and --blowup-energy 1e308 a
// run can reach T = 1e19 and still exit 0. The stop criteria (stability.h) stay as they are;
// this only makes sure such a run does not look like a result.
#pragma once

#include <string>
#include <vector>

#include "thermo.h"

namespace mini_md {

class RunawayWatch {
 public:
  // Limits are this factor times the run's own scale: no equilibrium LJ state, hot or cold,
  // dense or dilute, gets within a factor 1000 of them, so a warning is never a false alarm.
  static constexpr double kFactor = 1e3;

  // `initial`: the step-0 thermo. `set_temperature`: the highest temperature the run asked for
  // (scene temperature, thermostat target). Scales: T_ref = max(T0, set_temperature, 1);
  // E_ref = max(|PE0/atom|, KE0/atom, 1.5 T_ref, 1), since kinetic energy is 1.5 T per atom
  // and a run cannot gain more than the potential energy it starts with (NVE) or the thermostat
  // supplies.
  RunawayWatch(const ThermoState &initial, double set_temperature);

  // Texts of the warnings `now` newly triggers: T > kFactor T_ref, |E/atom| > kFactor E_ref,
  // either non-finite. Each kind (temperature, energy) is reported at most once per run.
  std::vector<std::string> check(const ThermoState &now);

  double temperature_limit() const { return temperature_limit_; }
  double energy_limit() const { return energy_limit_; }

 private:
  double temperature_limit_;
  double energy_limit_;
  bool warned_temperature_ = false;
  bool warned_energy_ = false;
};

}  // namespace mini_md
