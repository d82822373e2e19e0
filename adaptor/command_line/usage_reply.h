// What a Lantern command-line tool (lantern-render, lantern-imd) does with its parsed arguments
// before MPI starts: --help and --version answer on stdout, a usage error goes to stderr with the
// usage text. Header-only: the tools share nothing else.
#pragma once

#include <lantern/lantern.h>

#include <cstdio>
#include <optional>
#include <string>

namespace lantern_tools {

// `parsed` is the argument parser's answer: "" to run, "help", "version" or a usage error.
// Returns the exit code when the tool should stop now (0 after --help/--version, 2 after a usage
// error), nullopt when it should run.
inline std::optional<int> reply_to_usage(const char *tool, const std::string &parsed,
                                         const char *usage) {
  if (parsed.empty()) return std::nullopt;
  if (parsed == "help") {
    std::fputs(usage, stdout);
    return 0;
  }
  if (parsed == "version") {
    std::printf("%s (Lantern) %s\n", tool, lantern_version());
    return 0;
  }
  std::fprintf(stderr, "%s: %s\n%s", tool, parsed.c_str(), usage);
  return 2;
}

}  // namespace lantern_tools
