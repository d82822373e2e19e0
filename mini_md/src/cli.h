// Command-line parsing: argv -> RunConfig (plus the dt-sweep options). Pure; errors are
// reported as MdError with the offending option.
#pragma once

#include <string>
#include <vector>

#include "run_config.h"

namespace mini_md {

struct CommandLine {
  RunConfig run;
  bool help = false;
  bool dt_sweep = false;    // --dt-sweep: run the dt table instead of one simulation
  double sweep_time = 5.0;  // --sweep-time: simulated time per dt (LJ units)
  std::vector<double> sweep_dts{0.001, 0.002, 0.005, 0.01, 0.02};
  std::string csv_path;  // --csv FILE: also write the sweep table as CSV
};

CommandLine parse_command_line(int argc, const char *const *argv);
std::string usage_text();

}  // namespace mini_md
