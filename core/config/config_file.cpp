#include "core/config/config_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace lantern {
namespace {

const char *kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  return "not a file";
}

// Closes the descriptor on every way out.
struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::string read_config_file(const std::string &path, std::string *text, const char *kind) {
  // O_NONBLOCK: opening a FIFO that no one writes would otherwise wait for a writer; the type is
  // then checked on the opened file itself, so a file swapped for another in between is caught.
  const Descriptor file{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  if (file.fd < 0) return std::strerror(errno);
  struct stat st {};
  if (::fstat(file.fd, &st) != 0) return std::strerror(errno);
  if (!S_ISREG(st.st_mode))
    return std::string("is ") + kind_of(st.st_mode) + ", not a regular file (" + kind + ")";
  std::string read;
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::read(file.fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return std::strerror(errno);
    if (n == 0) break;
    if (int64_t(read.size()) + n > kMaxConfigBytes)
      return "is larger than " + std::to_string(kMaxConfigBytes >> 20) + " MiB (" + kind + ")";
    read.append(buffer, size_t(n));
  }
  *text = std::move(read);
  return {};
}

}  // namespace lantern
