// Receives the simulation's frames on a thread of its own, so that the simulation waits for
// lantern-imd only as long as a frame takes to cross the socket, not while it is rendered.
//
// The thread reads messages from the ImdConnection, validates every header (imd_protocol.h),
// reads each frame's coordinates into a buffer that grows only as bytes actually arrive (so a
// header announcing a huge frame costs nothing until its data comes, and the data is capped by
// --max-atoms and by the first frame's count), byte-swaps them if the server's byte order
// differs, and queues the frame. The queue holds `capacity` frames. When it is full the thread
// either waits (kBlock: the socket is not read, TCP's flow control holds the simulation at its
// next send, no frame is lost) or drops the oldest queued frame (kDropOldest: the simulation
// never waits for rendering; the dropped frames are counted).
//
// Steps: from the IMD_ENERGIES record sent before a frame (GROMACS, NAMD), plus step_offset
// (GROMACS 2022 fills the record after advancing its step counter: its frame of step s carries
// s + 1), else numbered first_step, first_step + every, ... (LAMMPS's fix imd sends no step: it
// sends at the steps that are multiples of its trate, the first after the start of the run).
//
// The end of the stream is an Event: kEnd when the server closed the connection between
// messages (the simulation ended), when the receiver was stopped, or after the idle limit;
// kError for a bad or truncated stream or a socket error. On leaving, the receiver sends
// IMD_DISCONNECT unless the server closed the connection first, so that the simulation goes on
// without it (LAMMPS: fix imd ... nowait yes).
//
// Ownership: owns the connection and its frames; next() hands a frame to the caller, who gives it
// back with recycle() for reuse. Thread-safety: next(), recycle() and the destructor from one
// thread (the main thread); the receiving thread is internal.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "imd_connection.h"

namespace lantern_imd {

struct Frame {
  int64_t step = 0;
  int64_t atoms = 0;
  std::vector<float> xyz;      // 3 * atoms, this machine's byte order
  double receive_seconds = 0;  // from the header's arrival to the last byte
};

struct Event {
  enum class Kind { kFrame, kEnd, kError };
  Kind kind = Kind::kEnd;
  std::unique_ptr<Frame> frame;  // kFrame
  std::string message;           // kEnd, kError
};

struct ReceiverOptions {
  int64_t max_atoms = 0;
  int64_t first_step = 0;
  int64_t every = 1;
  int64_t step_offset = 0;  // added to IMD_ENERGIES steps
  int capacity = 1;         // frames waiting to be rendered
  bool drop_oldest = false;
  double idle_seconds = 0;  // 0: wait for the simulation as long as it takes
};

class FrameReceiver {
 public:
  // Starts the thread. `stop` (set by a signal handler) ends the stream.
  FrameReceiver(std::unique_ptr<ImdConnection> connection, const ReceiverOptions &options,
                const std::atomic<bool> &stop);
  ~FrameReceiver();  // stops and joins the thread; IMD_DISCONNECT unless the server left
  FrameReceiver(const FrameReceiver &) = delete;
  FrameReceiver &operator=(const FrameReceiver &) = delete;

  Event next();  // blocks until a frame or the end
  void recycle(std::unique_ptr<Frame> frame);
  int64_t dropped() const { return dropped_; }

 private:
  void receive();  // the thread
  Event read_one(bool *stream_over);
  std::string read_coordinates(const Header &header, Frame *frame, bool *stream_over);
  std::string describe(ImdConnection::Read result, const std::string &what, size_t wanted,
                       bool *stream_over);
  void push(Event event);
  std::unique_ptr<Frame> spare_frame();

  std::unique_ptr<ImdConnection> connection_;
  const ReceiverOptions options_;
  const std::atomic<bool> &stop_;
  std::atomic<bool> leaving_{false};  // the destructor asks the thread to end
  std::atomic<bool> server_closed_{false};
  std::atomic<int64_t> dropped_{0};
  Limits limits_;
  int64_t frames_ = 0;
  std::optional<int64_t> pending_step_;  // from IMD_ENERGIES, for the next frame

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Event> queue_;
  bool finished_ = false;  // the thread queued its last event
  std::vector<std::unique_ptr<Frame>> spares_;
  std::thread thread_;
};

}  // namespace lantern_imd
