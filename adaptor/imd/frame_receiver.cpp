#include "frame_receiver.h"

#include <algorithm>
#include <chrono>

namespace lantern_imd {
namespace {

using Clock = std::chrono::steady_clock;
// Coordinates are read in slices of this many floats (4 MiB): the buffer grows only as fast as
// data arrives.
constexpr size_t kSliceFloats = size_t(1) << 20;

Event end_event(std::string message) {
  Event e;
  e.kind = Event::Kind::kEnd;
  e.message = std::move(message);
  return e;
}

Event error_event(std::string message) {
  Event e;
  e.kind = Event::Kind::kError;
  e.message = std::move(message);
  return e;
}

}  // namespace

FrameReceiver::FrameReceiver(std::unique_ptr<ImdConnection> connection,
                             const ReceiverOptions &options, const std::atomic<bool> &stop)
    : connection_(std::move(connection)), options_(options), stop_(stop) {
  limits_.max_atoms = options.max_atoms;
  thread_ = std::thread([this] { receive(); });
}

FrameReceiver::~FrameReceiver() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    leaving_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void FrameReceiver::receive() {
  for (;;) {
    bool over = false;
    Event event = read_one(&over);
    const bool frame = event.kind == Event::Kind::kFrame;
    push(std::move(event));
    if (!frame || leaving_) break;
  }
  // Leaving while the server is still there: tell it, so that it carries on without us.
  if (!server_closed_) static_cast<void>(connection_->send(MessageType::kDisconnect, 0));
}

std::string FrameReceiver::describe(ImdConnection::Read result, const std::string &what,
                                    size_t wanted, bool *stream_over) {
  using Read = ImdConnection::Read;
  *stream_over = true;
  switch (result) {
    case Read::kOk:
      *stream_over = false;
      return {};
    case Read::kClosed:
      server_closed_ = true;
      return "the simulation closed the connection in the middle of " + what + " (received " +
             std::to_string(connection_->bytes_read()) + " of " + std::to_string(wanted) +
             " bytes): truncated stream";
    case Read::kStopped:
      return {};
    case Read::kIdle:
      return "the simulation sent nothing for " + std::to_string(options_.idle_seconds) +
             " s (--idle-timeout) in the middle of " + what;
    case Read::kError:
      return connection_->error_message() + " while reading " + what;
  }
  return "unexpected read result";
}

Event FrameReceiver::read_one(bool *stream_over) {
  for (;;) {  // IMD_ENERGIES records come before their frame
    HeaderBytes bytes{};
    const auto result =
        connection_->read(bytes.data(), bytes.size(), options_.idle_seconds, leaving_);
    if (result == ImdConnection::Read::kClosed && connection_->bytes_read() == 0) {
      server_closed_ = true;
      return end_event("the simulation closed the connection (it ended, or left IMD)");
    }
    if (result == ImdConnection::Read::kIdle)
      return end_event("the simulation sent nothing for " +
                       std::to_string(int(options_.idle_seconds)) + " s (--idle-timeout)");
    if (result == ImdConnection::Read::kStopped) return end_event("stopped");
    if (std::string e = describe(result, "a message header", bytes.size(), stream_over); !e.empty())
      return error_event(e);
    const auto t0 = Clock::now();
    const Header header = decode_header(bytes);
    if (std::string e = check_server_header(header, limits_); !e.empty())
      return error_event("frame " + std::to_string(frames_ + 1) + ": " + e);
    if (header.type == int32_t(MessageType::kEnergies)) {
      unsigned char energies[kEnergiesBytes];
      const auto r = connection_->read(energies, sizeof(energies), options_.idle_seconds, leaving_);
      if (std::string e = describe(r, "an IMD_ENERGIES record", sizeof(energies), stream_over);
          !e.empty() || *stream_over)
        return *stream_over && e.empty() ? end_event("stopped") : error_event(e);
      pending_step_ = int64_t(energies_step(energies, connection_->swap())) + options_.step_offset;
      continue;
    }
    Event event;
    event.kind = Event::Kind::kFrame;
    event.frame = spare_frame();
    if (std::string e = read_coordinates(header, event.frame.get(), stream_over);
        !e.empty() || *stream_over) {
      recycle(std::move(event.frame));
      return *stream_over && e.empty() ? end_event("stopped") : error_event(e);
    }
    Frame &f = *event.frame;
    f.step = pending_step_ ? *pending_step_ : options_.first_step + frames_ * options_.every;
    f.receive_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    pending_step_.reset();
    limits_.expected_atoms = header.length;
    ++frames_;
    return event;
  }
}

std::string FrameReceiver::read_coordinates(const Header &header, Frame *frame, bool *stream_over) {
  frame->atoms = header.length;
  const size_t floats = 3 * size_t(header.length);
  frame->xyz.clear();  // keeps a recycled frame's capacity
  for (size_t have = 0; have < floats;) {
    const size_t slice = std::min(kSliceFloats, floats - have);
    frame->xyz.resize(have + slice);
    const auto r = connection_->read(frame->xyz.data() + have, slice * sizeof(float),
                                     options_.idle_seconds, leaving_);
    if (r != ImdConnection::Read::kOk) {
      const std::string what = "frame " + std::to_string(frames_ + 1) + "'s coordinates (" +
                               std::to_string(header.length) + " atoms)";
      std::string e = describe(r, what, floats * sizeof(float), stream_over);
      // describe() counted this slice only: say how far into the whole frame it got.
      const size_t got = have * sizeof(float) + connection_->bytes_read();
      if (r == ImdConnection::Read::kClosed)
        e = "the simulation closed the connection in the middle of " + what + " (received " +
            std::to_string(got) + " of " + std::to_string(floats * sizeof(float)) +
            " bytes): truncated stream";
      return e;
    }
    have += slice;
  }
  if (connection_->swap()) swap_words(frame->xyz.data(), int64_t(floats));
  return {};
}

void FrameReceiver::push(Event event) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (event.kind == Event::Kind::kFrame) {
    const auto frames_queued = [&] {
      return std::count_if(queue_.begin(), queue_.end(),
                           [](const Event &e) { return e.kind == Event::Kind::kFrame; });
    };
    if (options_.drop_oldest) {
      while (frames_queued() >= options_.capacity) {
        const auto oldest = std::find_if(queue_.begin(), queue_.end(), [](const Event &e) {
          return e.kind == Event::Kind::kFrame;
        });
        spares_.push_back(std::move(oldest->frame));
        queue_.erase(oldest);
        ++dropped_;
      }
    } else {
      changed_.wait(lock, [&] { return frames_queued() < options_.capacity || leaving_; });
      if (leaving_) return;
    }
  }
  queue_.push_back(std::move(event));
  changed_.notify_all();
}

Event FrameReceiver::next() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (queue_.empty()) {
    if (stop_) return end_event("stopped by a signal");
    changed_.wait_for(lock, std::chrono::milliseconds(100));
  }
  Event event = std::move(queue_.front());
  queue_.pop_front();
  changed_.notify_all();
  return event;
}

std::unique_ptr<Frame> FrameReceiver::spare_frame() {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (spares_.empty()) return std::make_unique<Frame>();
  std::unique_ptr<Frame> f = std::move(spares_.back());
  spares_.pop_back();
  return f;
}

void FrameReceiver::recycle(std::unique_ptr<Frame> frame) {
  if (!frame) return;
  const std::lock_guard<std::mutex> lock(mutex_);
  spares_.push_back(std::move(frame));
}

}  // namespace lantern_imd
