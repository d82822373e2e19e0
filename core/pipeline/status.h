// A stage's outcome inside Lantern: a C API status plus a message naming what went wrong.
#pragma once

#include <string>
#include <utility>

#include "lantern/lantern.h"

namespace lantern {

struct Status {
  lantern_status code = LANTERN_OK;
  std::string message;

  Status() = default;
  Status(lantern_status c, std::string m) : code(c), message(std::move(m)) {}
  bool ok() const { return code == LANTERN_OK; }
};

}  // namespace lantern
