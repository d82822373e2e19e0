// Work one rank does alone before it broadcasts the outcome (rank 0's overlays, movie encoder),
// with exceptions turned into a status: an exception there (an allocation that fails, a thread
// that cannot start) would unwind past the broadcast and leave every other rank waiting in it.
#pragma once

#include <exception>
#include <new>
#include <stdexcept>
#include <string>

#include "core/common/status.h"

namespace lantern {

// f() -> Status; an exception becomes kOutOfMemory (bad_alloc, length_error: sizes beyond what
// can be allocated) or kInternal (anything else), its message after `what`.
template <typename F>
Status guarded_status(const std::string &what, F &&f) {
  try {
    return f();
  } catch (const std::bad_alloc &) {
    return {StatusCode::kOutOfMemory, what + ": out of memory"};
  } catch (const std::length_error &e) {
    return {StatusCode::kOutOfMemory, what + ": out of memory (" + e.what() + ")"};
  } catch (const std::exception &e) {
    return {StatusCode::kInternal, what + ": " + e.what()};
  } catch (...) {
    return {StatusCode::kInternal, what + ": an unknown exception"};
  }
}

}  // namespace lantern
