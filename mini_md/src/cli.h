// Command-line parsing: argv -> RunConfig (plus the dt-sweep options). Pure; errors are
// reported as MdError with the offending option.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "run_config.h"

namespace mini_md {

struct CommandLine {
  RunConfig run;
  bool help = false;
  bool version = false;     // --version: print the version and run nothing
  bool dt_sweep = false;    // --dt-sweep: run the dt table instead of one simulation
  double sweep_time = 5.0;  // --sweep-time: simulated time per dt (LJ units)
  std::vector<double> sweep_dts{0.001, 0.002, 0.005, 0.01, 0.02};
  std::string csv_path;  // --csv FILE: also write the sweep table as CSV
};

// One numeric option: its range and where its value goes. Every numeric option is parsed and
// range-checked through the one table numeric_options(), so none can accept NaN, infinity or an
// absurd value that its neighbours reject; the error names the option, the text and the range.
struct NumericOption {
  std::string name;            // "--temp"
  double min = 0.0;            // smallest allowed value (excluded if min_exclusive)
  bool min_exclusive = false;  // (min, ...] rather than [min, ...]
  double max = 0.0;            // largest allowed value; +inf: any finite value
  // Exactly one is set: integer options are parsed as integers (no "1e3", no "2.5").
  void (*store_integer)(CommandLine &, int64_t) = nullptr;
  void (*store_real)(CommandLine &, double) = nullptr;
  bool integer() const { return store_integer != nullptr; }
};

const std::vector<NumericOption> &numeric_options();
// "[0, 10000]", "(0, 1]", "(0, inf)": the range as error messages and --help print it.
std::string range_text(const NumericOption &option);

// Throws MdError naming the option at fault (unknown, missing value, out of range).
CommandLine parse_command_line(int argc, const char *const *argv);
std::string usage_text();

}  // namespace mini_md
