// A TCP connection to an IMD server (the simulation), from the handshake on: connects (retrying
// while the simulation is not listening yet), checks the handshake, answers IMD_GO, and then
// reads exact byte counts and sends headers.
//
// Reads wait in poll() in short slices so that a stop request (a signal) is noticed within
// 100 ms and a simulation that sends nothing for a while (paused, between runs, minimizing) is
// simply waited for; an optional idle limit ends the wait. Writes use MSG_NOSIGNAL, so a
// simulation that went away gives an error, never SIGPIPE.
//
// Ownership: owns the socket (closed by the destructor). Thread-safety: one thread at a time.
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <string>

#include "imd_protocol.h"

namespace lantern_imd {

class ImdConnection {
 public:
  // Connects to host:port, retrying for up to connect_seconds while the connection is refused
  // (the simulation may start listening later), then reads the handshake and answers IMD_GO.
  // "" and *out, or an error naming the address and the reason.
  static std::string open(const std::string &host, const std::string &port, double connect_seconds,
                          const std::atomic<bool> &stop, std::unique_ptr<ImdConnection> *out);
  ~ImdConnection();
  ImdConnection(const ImdConnection &) = delete;
  ImdConnection &operator=(const ImdConnection &) = delete;

  enum class Read {
    kOk,       // all bytes read
    kClosed,   // the server closed the connection (see bytes_read for how far it got)
    kStopped,  // `stop` was set while waiting
    kIdle,     // nothing arrived for idle_seconds
    kError,    // a socket error (error_message())
  };
  // Reads exactly n bytes into `into`. idle_seconds <= 0: wait as long as it takes.
  Read read(void *into, size_t n, double idle_seconds, const std::atomic<bool> &stop);
  size_t bytes_read() const { return bytes_read_; }  // of the last read()
  const std::string &error_message() const { return error_; }

  // Sends a header (IMD_DISCONNECT, IMD_TRATE, ...). "" or the error.
  std::string send(MessageType type, int32_t length);

  bool swap() const { return swap_; }  // payloads are in the other byte order
  const std::string &address() const { return address_; }

 private:
  ImdConnection(int fd, std::string address) : fd_(fd), address_(std::move(address)) {}

  int fd_ = -1;
  std::string address_;
  bool swap_ = false;
  size_t bytes_read_ = 0;
  std::string error_;
};

}  // namespace lantern_imd
