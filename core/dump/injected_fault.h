// A test hook for the dump's failure paths: makes this process report one of the dump's HDF5
// steps as failed, so a test can fail one rank of several (as a full disk or a permission change
// on one node would) and check that every rank returns the same error and none hangs.
//
// Only tests call inject_dump_fault(); without it nothing ever fails here. Process-wide: the
// armed fault lives in the environment variable LANTERN_INJECT_DUMP_FAULT (so that a test
// linking core directly reaches the copy of core inside the shared C library too). Not
// thread-safe (setenv; the dump stage runs on the thread that calls lantern_execute).
#pragma once

#include <string>

namespace lantern {

// The next dump step on this process whose description contains `what` (e.g.
// "position/value: write", "flush", "file is writable") fails once. Empty `what` clears it.
void inject_dump_fault(const std::string &what);

// Used by CollectiveCalls: true (once) when `description` matches the injected fault.
bool take_injected_fault(const std::string &description);

}  // namespace lantern
