// A test hook for failure paths that are hard to cause on purpose: makes this process report one
// named step as failed, so a test can fail one rank of several (as a full disk, a permission
// change on one node or memory running out there would) and check that every rank returns the
// same error and none hangs. The dump's HDF5 steps (core/dump/collective_calls.h) and the PNG
// bands a rank compresses for the root (core/output/png/png_across_ranks.cpp) ask it.
//
// Only tests call inject_fault(); without it nothing ever fails here. Process-wide: the armed
// fault lives in the environment variable LANTERN_INJECT_FAULT (so that a test linking core
// directly reaches the copy of core inside the shared C library too). Not thread-safe (setenv;
// the steps that ask run on the thread that calls lantern_execute).
#pragma once

#include <string>

namespace lantern {

// The next step on this process whose description contains `what` (e.g. "position/value:
// write", "flush", "file is writable", "png: deflate band") fails once. Empty `what` clears it.
void inject_fault(const std::string &what);

// True (once) when `description` matches the injected fault.
bool take_injected_fault(const std::string &description);

}  // namespace lantern
