// A stage's outcome inside Lantern: a status code plus a message naming what went wrong.
//
// This is core's one error convention: a function that can fail returns a Status (OK, or the code
// that fits where the failure is known and a message naming what is at fault) and hands results
// back through pointer out-parameters (factories: static Status create(..., std::unique_ptr<T> *)).
// A caller keeps a lower stage's code and only adds context to its message, with with_context().
// The codes have the numeric values of the C API's lantern_status (adaptor/), which translates
// them one to one; core itself never sees the public header.
#pragma once

#include <string>
#include <utility>

namespace lantern {

// Append-only, like lantern_status: a value never changes meaning.
enum class StatusCode {
  kOk = 0,
  kNullArgument = 1,     // a required pointer argument was NULL
  kInvalidArgument = 2,  // an argument's value is out of range or inconsistent
  kConfig = 3,           // the configuration is malformed or has an invalid key/value
  kIo = 4,               // a file could not be read or written; later steps retry
  kGl = 5,               // the OpenGL back end failed
  kMpi = 6,              // an MPI call failed or the communicator is invalid
  kOutOfMemory = 7,      // an allocation failed; the step was skipped
  kInternal = 8          // a bug in Lantern
};

struct Status {
  StatusCode code = StatusCode::kOk;
  std::string message;

  Status() = default;
  Status(StatusCode c, std::string m) : code(c), message(std::move(m)) {}
  bool ok() const { return code == StatusCode::kOk; }
};

// `s` with `prefix` in front of its message (e.g. "scenes 'top': "); the code is kept, and an
// OK status stays OK.
inline Status with_context(const std::string &prefix, Status s) {
  if (!s.ok()) s.message.insert(0, prefix);
  return s;
}

}  // namespace lantern
