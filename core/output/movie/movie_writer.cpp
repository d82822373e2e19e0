#include "core/output/movie/movie_writer.h"

#include <chrono>
#include <utility>

#include "core/common/ms_since.h"

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

Status MovieWriter::open(const MovieConfig &movie, const std::string &path, int width, int height,
                         std::unique_ptr<MovieWriter> *out) {
  std::unique_ptr<MovieEncoder> encoder;
  if (Status s = MovieEncoder::open(movie, path, width, height, &encoder); !s.ok()) return s;
  out->reset(new MovieWriter(movie, path, width, height, std::move(encoder)));
  return {};
}

MovieWriter::MovieWriter(const MovieConfig &movie, std::string path, int width, int height,
                         std::unique_ptr<MovieEncoder> encoder)
    : config_(movie),
      path_(std::move(path)),
      width_(width),
      height_(height),
      encoder_(std::move(encoder)) {
  thread_ = std::thread([this] { run(); });
}

MovieWriter::~MovieWriter() {
  static_cast<void>(finish());
}

void MovieWriter::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    work_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (queue_.empty()) break;  // stopped, and everything queued is encoded
    Item item = std::move(queue_.front());
    queue_.pop_front();
    const bool skip = failed_;
    lock.unlock();
    const auto t0 = Clock::now();
    const Status encoded = skip ? Status() : encoder_->encode(item.rgba.data(), item.index);
    const double ms = ms_since(t0);
    lock.lock();
    free_.push_back(std::move(item.rgba));
    encode_ms_ = ms;
    written_ = encoder_->frames_written();
    if (!encoded.ok() && !failed_) {
      failed_ = true;
      error_ = encoded;
      for (Item &waiting : queue_) free_.push_back(std::move(waiting.rgba));
      queue_.clear();
    }
    space_.notify_all();
  }
  const bool skip = failed_;
  lock.unlock();
  const Status finished = skip ? Status() : encoder_->finish();
  lock.lock();
  written_ = encoder_->frames_written();
  if (!finished.ok() && !failed_) {
    failed_ = true;
    error_ = finished;
  }
}

Status MovieWriter::submit(const Frame &frame) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (failed_ || finished_) {
    if (!failed_ || error_reported_) return {};
    error_reported_ = true;
    return with_context("the movie stopped (images go on): ", error_);
  }
  if (frame.width != width_ || frame.height != height_ ||
      frame.rgba.size() != size_t(width_) * size_t(height_) * 4)
    return {StatusCode::kInvalidArgument,
            "movie '" + path_ + "': a " + std::to_string(frame.width) + " x " +
                std::to_string(frame.height) + " frame for a movie of " + std::to_string(width_) +
                " x " + std::to_string(height_)};
  const int64_t index = next_index_++;
  waited_ms_ = 0.0;
  if (queue_.size() >= size_t(config_.queue)) {
    if (config_.when_behind == MovieWhenBehind::kDrop) {
      ++dropped_;
      return {};
    }
    const auto t0 = Clock::now();
    space_.wait(lock, [this] { return queue_.size() < size_t(config_.queue) || failed_; });
    waited_ms_ = ms_since(t0);
    if (failed_) {
      error_reported_ = true;
      return with_context("the movie stopped (images go on): ", error_);
    }
  }
  std::vector<uint8_t> buffer;
  if (!free_.empty()) {
    buffer = std::move(free_.back());
    free_.pop_back();
  }
  lock.unlock();  // only this thread adds frames: the copy needs no lock
  buffer.assign(frame.rgba.begin(), frame.rgba.end());
  lock.lock();
  queue_.push_back(Item{index, std::move(buffer)});
  work_.notify_one();
  return {};
}

MovieProgress MovieWriter::progress() const {
  std::lock_guard<std::mutex> lock(mutex_);
  MovieProgress p;
  p.file = path_;
  p.encoder = encoder_->encoder_name();
  p.submitted = next_index_;
  p.written = written_;
  p.queued = int64_t(queue_.size());
  p.dropped = dropped_;
  p.waited_ms = waited_ms_;
  p.encode_ms = encode_ms_;
  if (failed_) p.error = error_.message;
  return p;
}

Status MovieWriter::finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return finish_status_;
    finished_ = true;
    stop_ = true;
  }
  work_.notify_one();
  if (thread_.joinable()) thread_.join();
  std::lock_guard<std::mutex> lock(mutex_);
  finish_status_ = failed_ ? error_ : Status();
  return finish_status_;
}

}  // namespace lantern
