// Crash-safe file replacement: write everything to a temporary file next to the target, then
// rename() it over the final name. A process that dies mid-write leaves at worst a hidden
// ".<name>.tmp<pid>-<n><ext>" file, never a truncated file at the final name. (No fsync: this
// protects against process crashes, not against power loss, to keep per-frame cost low.)
//
// Thread-safe: temporary names are unique per process and call.
#pragma once

#include <cstddef>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

#include "core/common/status.h"

namespace lantern {

// Creates the parent directories of `path` (no-op if there are none). OK, or kIo with a message
// naming the directory and the OS reason.
Status create_parent_directories(const std::string &path);

// The temporary name used for `final_path`: same directory, hidden, unique per process and
// call, ending in `extension` (e.g. ".png", so libraries that choose a format by extension
// still work). Exposed for tests.
std::string temporary_path_for(const std::string &final_path, const std::string &extension);

// Writes `final_path` atomically: creates parent directories, creates the temporary file
// (exclusively, mode 0644 minus umask), calls `write(temp_path)` which must fill it and return
// OK or a failed Status, then renames. On any failure the temporary file is removed and the
// message names the path and the reason; `final_path` is then untouched. The code is kIo, or
// `write`'s own code when it failed. Exceptions thrown by `write` are caught and reported (kIo).
Status write_atomically(const std::string &final_path, const std::string &extension,
                        const std::function<Status(const std::string &)> &write);

// Writes all `size` bytes of `data` to the open descriptor `fd`, retrying on short writes and
// EINTR. Returns 0, or the errno of the write that failed.
int write_all(int fd, const void *data, size_t size);

// Convenience: atomically writes `size` bytes from `data` (not owned; read during the call).
// OK or kIo.
Status write_bytes_atomically(const std::string &final_path, const void *data, size_t size);

// Removes from `directory` the temporary files a killed process left there: only names of the
// form temporary_path_for makes (".<name>.tmp<pid>-<n>[.ext]"), only regular files modified
// before `started`, and only when no process <pid> runs on this host (a run writing into the same
// folder keeps its files). Best effort: errors are ignored. Returns the names removed.
std::vector<std::string> remove_stale_temporaries(const std::string &directory,
                                                  std::time_t started);

}  // namespace lantern
