#include "imd_connection.h"

#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

namespace lantern_imd {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kSliceMs = 100;  // how often a wait looks at the stop flag

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct AddressList {
  addrinfo *list = nullptr;
  ~AddressList() {
    if (list) freeaddrinfo(list);
  }
};

// One connection attempt to each address of host:port: a connected socket, or -1 and the errno
// of the last attempt.
int try_connect(const addrinfo *list, int *error) {
  for (const addrinfo *a = list; a; a = a->ai_next) {
    const int fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {
      *error = errno;
      continue;
    }
    if (connect(fd, a->ai_addr, a->ai_addrlen) == 0) return fd;
    *error = errno;
    close(fd);
  }
  return -1;
}

}  // namespace

std::string ImdConnection::open(const std::string &host, const std::string &port,
                                double connect_seconds, const std::atomic<bool> &stop,
                                std::unique_ptr<ImdConnection> *out) {
  const std::string address = host + ":" + port;
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  AddressList addresses;
  if (const int rc = getaddrinfo(host.c_str(), port.c_str(), &hints, &addresses.list); rc != 0)
    return address + ": " + gai_strerror(rc);
  const auto t0 = Clock::now();
  int fd = -1, error = 0;
  while ((fd = try_connect(addresses.list, &error)) < 0) {
    // Refused: nobody listens yet (the simulation has not reached its IMD set-up). Retry.
    if (error != ECONNREFUSED || seconds_since(t0) >= connect_seconds || stop)
      return address + ": cannot connect (" + std::strerror(error) + ")" +
             (error == ECONNREFUSED ? " after trying for " + std::to_string(int(connect_seconds)) +
                                          " s (--connect-timeout)"
                                    : "");
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  std::unique_ptr<ImdConnection> c(new ImdConnection(fd, address));
  // The server sends its handshake at once on accepting; allow it a generous 30 s (it may be
  // busy), then answer IMD_GO, which LAMMPS and GROMACS wait for for one second only.
  HeaderBytes handshake{};
  switch (c->read(handshake.data(), handshake.size(), 30.0, stop)) {
    case Read::kOk:
      break;
    case Read::kClosed:
      return address + ": the server closed the connection before its IMD handshake";
    case Read::kStopped:
      return address + ": stopped while waiting for the IMD handshake";
    case Read::kIdle:
      return address + ": no IMD handshake within 30 s (is this port an IMD server?)";
    case Read::kError:
      return address + ": " + c->error_message();
  }
  if (std::string e = check_handshake(handshake, &c->swap_); !e.empty()) return address + ": " + e;
  if (std::string e = c->send(MessageType::kGo, 0); !e.empty()) return address + ": " + e;
  *out = std::move(c);
  return {};
}

ImdConnection::~ImdConnection() {
  if (fd_ >= 0) close(fd_);
}

ImdConnection::Read ImdConnection::read(void *into, size_t n, double idle_seconds,
                                        const std::atomic<bool> &stop) {
  auto *p = static_cast<unsigned char *>(into);
  bytes_read_ = 0;
  auto last_data = Clock::now();
  while (bytes_read_ < n) {
    if (stop) return Read::kStopped;
    pollfd pfd{fd_, POLLIN, 0};
    const int ready = poll(&pfd, 1, kSliceMs);
    if (ready < 0) {
      if (errno == EINTR) continue;  // a signal: the loop looks at `stop`
      error_ = std::string("poll: ") + std::strerror(errno);
      return Read::kError;
    }
    if (ready == 0) {
      if (idle_seconds > 0 && seconds_since(last_data) >= idle_seconds) return Read::kIdle;
      continue;
    }
    const ssize_t got = recv(fd_, p + bytes_read_, n - bytes_read_, 0);
    if (got == 0) return Read::kClosed;
    if (got < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      if (errno == ECONNRESET) return Read::kClosed;  // the simulation went away
      error_ = std::string("recv: ") + std::strerror(errno);
      return Read::kError;
    }
    bytes_read_ += size_t(got);
    last_data = Clock::now();
  }
  return Read::kOk;
}

std::string ImdConnection::send(MessageType type, int32_t length) {
  const HeaderBytes h = encode_header(type, length);
  size_t sent = 0;
  while (sent < h.size()) {
    const ssize_t n = ::send(fd_, h.data() + sent, h.size() - sent, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return std::string("sending ") + type_name(int32_t(type)) + ": " + std::strerror(errno);
    }
    sent += size_t(n);
  }
  return {};
}

}  // namespace lantern_imd
