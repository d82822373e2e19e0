// The one exception type of mini_md. Thrown collectively (on every rank) once the ranks agree
// that the run cannot continue, so that main() can report and exit with a non-zero code.
#pragma once

#include <stdexcept>
#include <string>

namespace mini_md {

class MdError : public std::runtime_error {
 public:
  explicit MdError(const std::string &what) : std::runtime_error(what) {}
};

}  // namespace mini_md
