#include "core/output/stats_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/output/atomic_file.h"

namespace lantern {

StatsWriter::~StatsWriter() {
  if (fd_ >= 0) ::close(fd_);
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
    if (fd_ < 0)
      return {StatusCode::kIo, "cannot open stats file '" + path_ + "': " + std::strerror(errno)};
  }
  const char *data = line.data();
  size_t left = line.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, data, left);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int reason = errno;
      ::close(fd_);
      fd_ = -1;
      return {StatusCode::kIo, "cannot write stats file '" + path_ + "': " + std::strerror(reason)};
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
