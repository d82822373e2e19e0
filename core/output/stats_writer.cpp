#include "core/output/stats_writer.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

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

Status append_json_line(const std::string &path, const nlohmann::json &record) {
  StatsWriter writer(path);
  return writer.append(record);
}

}  // namespace lantern
