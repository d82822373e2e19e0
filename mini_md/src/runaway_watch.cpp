#include "runaway_watch.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mini_md {

namespace {

// True when `value` is beyond `limit` in magnitude or not a number (NaN fails every comparison).
bool beyond(double value, double limit) {
  return !(std::fabs(value) <= limit);
}

}  // namespace

RunawayWatch::RunawayWatch(const ThermoState &initial, double set_temperature) {
  const double t_ref = std::max({initial.temperature, set_temperature, 1.0});
  const double e_ref =
      std::max({std::fabs(initial.pe_atom), std::fabs(initial.ke_atom), 1.5 * t_ref, 1.0});
  temperature_limit_ = kFactor * t_ref;
  energy_limit_ = kFactor * e_ref;
}

std::vector<std::string> RunawayWatch::check(const ThermoState &now) {
  std::vector<std::string> warnings;
  const std::string advice =
      "; the run is no longer physical although no stop criterion fired (see --dt, "
      "--neigh-check, --neigh-every, --blowup-energy)";
  if (!warned_temperature_ && beyond(now.temperature, temperature_limit_)) {
    warned_temperature_ = true;
    std::ostringstream s;
    s << "step " << now.step << ": temperature " << now.temperature << " is beyond "
      << temperature_limit_ << " (" << kFactor << " x the initial or set temperature, at least 1)"
      << advice;
    warnings.push_back(s.str());
  }
  if (!warned_energy_ && beyond(now.etot_atom, energy_limit_)) {
    warned_energy_ = true;
    std::ostringstream s;
    s << "step " << now.step << ": energy per atom " << now.etot_atom << " is beyond +-"
      << energy_limit_ << " (" << kFactor << " x the initial energy scale per atom, at least 1)"
      << advice;
    warnings.push_back(s.str());
  }
  return warnings;
}

}  // namespace mini_md
