// Test support: a file-size limit for this process (RLIMIT_FSIZE), as a full disk would impose,
// with SIGXFSZ ignored so a write past it fails with EFBIG instead of ending the process. The
// destructor restores both (RAII). Process-wide: only for tests that run alone in their process.
#pragma once

#include <signal.h>
#include <sys/resource.h>

namespace lantern::testing {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &saved_);
    previous_ = signal(SIGXFSZ, SIG_IGN);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &saved_);
    signal(SIGXFSZ, previous_);
  }
  FileSizeLimit(const FileSizeLimit &) = delete;
  FileSizeLimit &operator=(const FileSizeLimit &) = delete;

 private:
  rlimit saved_{};
  sighandler_t previous_ = SIG_DFL;
};

}  // namespace lantern::testing
