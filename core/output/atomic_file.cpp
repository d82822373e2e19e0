#include "core/output/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <regex>
#include <system_error>

namespace lantern {

namespace fs = std::filesystem;

namespace {

std::string os_reason(int error) {
  return std::strerror(error);
}

// Removes the temporary file, ignoring errors: it is best effort on an already failing path.
void remove_quietly(const std::string &path) {
  std::error_code ignored;
  fs::remove(path, ignored);
}

}  // namespace

int write_all(int fd, const void *data, size_t size) {
  const char *p = static_cast<const char *>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    p += n;
    size -= static_cast<size_t>(n);
  }
  return 0;
}

Status create_parent_directories(const std::string &path) {
  const fs::path parent = fs::path(path).parent_path();
  if (parent.empty()) return {};
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec)
    return {StatusCode::kIo, "cannot create directory '" + parent.string() + "' for '" + path +
                                 "': " + ec.message()};
  if (!fs::is_directory(parent, ec))
    return {StatusCode::kIo,
            "cannot write '" + path + "': '" + parent.string() + "' is not a directory"};
  return {};
}

std::string temporary_path_for(const std::string &final_path, const std::string &extension) {
  static std::atomic<unsigned long> counter{0};
  const fs::path target(final_path);
  const std::string name = "." + target.filename().string() + ".tmp" +
                           std::to_string(static_cast<long>(::getpid())) + "-" +
                           std::to_string(counter.fetch_add(1)) + extension;
  return (target.parent_path() / name).string();
}

Status write_atomically(const std::string &final_path, const std::string &extension,
                        const std::function<Status(const std::string &)> &write) {
  if (final_path.empty()) return {StatusCode::kIo, "cannot write a file with an empty name"};
  const std::string where = "cannot write '" + final_path + "': ";
  if (fs::path(final_path).filename().empty())
    return {StatusCode::kIo, where + "it names a directory, not a file"};
  if (Status s = create_parent_directories(final_path); !s.ok()) return s;

  const std::string temp = temporary_path_for(final_path, extension);
  // Create the file ourselves first, so that an unwritable directory is reported with the OS
  // reason (image libraries often just say "could not open").
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return {StatusCode::kIo, where + os_reason(errno)};
  ::close(fd);

  Status written;
  try {
    written = write(temp);
  } catch (const std::exception &e) {
    written = {StatusCode::kIo, e.what()};
  } catch (...) {
    written = {StatusCode::kIo, "unknown error"};
  }
  if (!written.ok()) {
    remove_quietly(temp);
    return with_context(where, std::move(written));
  }
  if (std::rename(temp.c_str(), final_path.c_str()) != 0) {
    const int reason = errno;
    remove_quietly(temp);
    return {StatusCode::kIo,
            "cannot rename '" + temp + "' to '" + final_path + "': " + os_reason(reason)};
  }
  return {};
}

std::vector<std::string> remove_stale_temporaries(const std::string &directory,
                                                  std::time_t started) {
  // ".<name>.tmp<pid>-<counter>" and an optional extension (temporary_path_for).
  static const std::regex temporary(R"(^\..+\.tmp([0-9]{1,10})-[0-9]{1,20}(\.[A-Za-z0-9]{1,8})?$)");
  std::vector<std::string> removed;
  std::error_code ec;
  for (fs::directory_iterator it(directory.empty() ? "." : directory, ec), end; !ec && it != end;
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::smatch match;
    if (!std::regex_match(name, match, temporary)) continue;
    struct stat st {};
    if (::lstat(it->path().c_str(), &st) != 0 || !S_ISREG(st.st_mode) || st.st_mtime >= started)
      continue;
    const long pid = std::stol(match[1].str());
    if (pid > 0 && pid <= std::numeric_limits<pid_t>::max() &&
        (::kill(pid_t(pid), 0) == 0 || errno == EPERM))
      continue;  // that process still runs here: maybe writing it now
    std::error_code ignored;
    if (fs::remove(it->path(), ignored)) removed.push_back(it->path().string());
  }
  return removed;
}

Status write_bytes_atomically(const std::string &final_path, const void *data, size_t size) {
  const std::string extension = fs::path(final_path).extension().string();
  return write_atomically(final_path, extension, [&](const std::string &temp) -> Status {
    const int fd = ::open(temp.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd < 0) return {StatusCode::kIo, os_reason(errno)};
    int error = write_all(fd, data, size);
    if (::close(fd) != 0 && error == 0) error = errno;
    if (error != 0) return {StatusCode::kIo, os_reason(error)};
    return {};
  });
}

}  // namespace lantern
