#include "core/output/stats_writer.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "core/output/atomic_file.h"

namespace lantern {

StatsWriter::~StatsWriter() {
  if (fd_ >= 0) ::close(fd_);
}

// kIo naming the file and the OS reason; closes the file, so the next append opens it again.
Status StatsWriter::fail(const char *what, int reason, const std::string &more) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  return {StatusCode::kIo, what + path_ + "': " + std::strerror(reason) + more};
}

Status StatsWriter::append(const nlohmann::json &record) {
  std::string line;
  try {
    // Replace invalid UTF-8 rather than throw: a stats line must never stop a run.
    line = record.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  } catch (const std::exception &e) {
    return {StatusCode::kInternal, "cannot format a stats line for '" + path_ + "': " + e.what()};
  }
  if (fd_ < 0) {
    if (Status s = create_parent_directories(path_); !s.ok()) return s;
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd_ < 0) return fail("cannot open stats file '", errno);
    if (Status s = cut_incomplete_last_line(); !s.ok()) return s;
  }
  // Where the line starts: a write cut short (a full disk) is truncated back to it, so the file
  // keeps whole lines only and the next line does not continue a broken one.
  struct stat before {};
  if (::fstat(fd_, &before) != 0) return fail("cannot write stats file '", errno);
  const char *data = line.data();
  size_t left = line.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, data, left);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int reason = errno;
      if (::ftruncate(fd_, before.st_size) != 0)
        return fail("cannot write stats file '", reason,
                    std::string("; its last line is incomplete (truncating it failed: ") +
                        std::strerror(errno) + ")");
      return fail("cannot write stats file '", reason);
    }
    data += n;
    left -= static_cast<size_t>(n);
  }
  return {};
}

Status StatsWriter::close() {
  if (fd_ < 0) return {};
  const int fd = std::exchange(fd_, -1);
  if (::close(fd) != 0)
    return {StatusCode::kIo, "cannot write stats file '" + path_ + "': " + std::strerror(errno)};
  return {};
}

// A regular file that does not end in a newline holds the start of a line whose writer was killed:
// it is cut back to its last newline. Reads the tail backwards in blocks (a line is a few kB at
// most) through a read-only descriptor of its own; where the file cannot be read (write-only
// permissions) it is left as it is.
Status StatsWriter::cut_incomplete_last_line() {
  struct stat st {};
  if (::fstat(fd_, &st) != 0) return fail("cannot open stats file '", errno);
  if (!S_ISREG(st.st_mode) || st.st_size == 0) return {};
  const int in = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  if (in < 0) return {};
  char last = 0;
  if (::pread(in, &last, 1, st.st_size - 1) != 1 || last == '\n') {  // the usual case: ends whole
    ::close(in);
    return {};
  }
  off_t end = st.st_size, cut = 0;
  bool read_all = true;
  char block[4096];
  while (end > 0) {
    const off_t start = end > off_t(sizeof block) ? end - off_t(sizeof block) : 0;
    const auto want = size_t(end - start);
    const ssize_t got = ::pread(in, block, want, start);
    if (got < 0 && errno == EINTR) continue;
    if (got != ssize_t(want)) {
      read_all = false;
      break;
    }
    size_t k = want;
    while (k > 0 && block[k - 1] != '\n') --k;
    if (k > 0) {
      cut = start + off_t(k);
      break;
    }
    end = start;
  }
  ::close(in);
  if (!read_all) return {};
  if (::ftruncate(fd_, cut) != 0) return fail("cannot cut an incomplete last line of '", errno);
  return {};
}

Status append_json_line(const std::string &path, const nlohmann::json &record) {
  StatsWriter writer(path);
  if (Status s = writer.append(record); !s.ok()) return s;
  return writer.close();
}

}  // namespace lantern
