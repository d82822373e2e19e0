// A full disk, portably: RLIMIT_FSIZE makes every write past `bytes` in any file of this process
// fail (a write that crosses the limit is cut short, the next one fails with EFBIG), which drives
// the same code paths as ENOSPC on a full file system - a short write, then a failed one - with
// no mount (CI may not allow one) and no root. SIGXFSZ, which the kernel sends on such a write,
// is ignored meanwhile (its default action ends the process). RAII: the soft limit and the signal
// disposition are restored on destruction. Process-wide: hold it only around the write under test.
#pragma once

#include <signal.h>
#include <sys/resource.h>

#include <cstdint>

namespace lantern::testing {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(int64_t bytes) {
    getrlimit(RLIMIT_FSIZE, &saved_);
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigaction(SIGXFSZ, &ignore, &saved_action_);
    rlimit limited = saved_;
    limited.rlim_cur = rlim_t(bytes);
    setrlimit(RLIMIT_FSIZE, &limited);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &saved_);
    sigaction(SIGXFSZ, &saved_action_, nullptr);
  }
  FileSizeLimit(const FileSizeLimit &) = delete;
  FileSizeLimit &operator=(const FileSizeLimit &) = delete;

 private:
  rlimit saved_{};
  struct sigaction saved_action_ {};
};

}  // namespace lantern::testing
