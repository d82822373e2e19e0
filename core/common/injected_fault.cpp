#include "core/common/injected_fault.h"

#include <cstdlib>

namespace lantern {
namespace {

// Kept in the environment rather than in a variable: tests link core statically and also reach
// it through the shared C library, which holds a second copy of core's variables; the process
// environment is the one thing both copies see.
constexpr const char *kVariable = "LANTERN_INJECT_FAULT";

}  // namespace

void inject_fault(const std::string &what) {
  if (what.empty())
    unsetenv(kVariable);
  else
    setenv(kVariable, what.c_str(), 1);
}

bool take_injected_fault(const std::string &description) {
  const char *armed = std::getenv(kVariable);
  if (!armed || !*armed || description.find(armed) == std::string::npos) return false;
  unsetenv(kVariable);
  return true;
}

}  // namespace lantern
