// A scene's movie, encoded on a background thread so that a simulation step never waits for the
// encoder (rank 0 runs it; core/pipeline hands it the composited frames).
//
// submit() copies the frame into a bounded queue (output.movie.queue frames) and returns. When
// the queue is full the encoder is behind, and output.movie.when_behind decides:
// - drop (the default): the frame is left out of the movie and counted (progress().dropped; the
//   stats line shows it). It keeps its place on the movie's clock: the previous frame stays on
//   screen for its time, so the movie's time still follows the simulation's steps.
// - wait: submit() waits until the encoder has taken a frame (progress().waited_ms).
// Memory stays bounded at `queue` + 1 frames.
//
// If the encoder fails (full disk, ...) the movie stops: the file keeps the frames written
// before, submit() returns the error once (kIo naming the file) and then ignores frames, so the
// images and the simulation go on.
//
// Thread-safety: one owner thread calls submit(), progress() and finish(); the encoder thread
// only encodes. The destructor finishes the movie.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/common/status.h"
#include "core/config/config.h"
#include "core/output/movie/movie_encoder.h"
#include "core/view/frame.h"

namespace lantern {

// Where a movie stands, for the stats line.
struct MovieProgress {
  std::string file;
  std::string encoder;     // e.g. "libx264"
  int64_t submitted = 0;   // frames handed over, dropped ones included
  int64_t written = 0;     // frames in the file
  int64_t queued = 0;      // frames waiting for the encoder now
  int64_t dropped = 0;     // frames left out because the queue was full (when_behind: drop)
  double waited_ms = 0.0;  // how long the last submit() waited (when_behind: wait)
  double encode_ms = 0.0;  // the encoder's time for the last frame it took
  std::string error;       // why the movie stopped; "" while it runs
};

class MovieWriter {
 public:
  // Opens the movie (MovieEncoder::open: kConfig for settings this build cannot encode, kIo when
  // the file cannot be written) and starts the encoder thread.
  static Status open(const MovieConfig &movie, const std::string &path, int width, int height,
                     std::unique_ptr<MovieWriter> *out);
  ~MovieWriter();
  MovieWriter(const MovieWriter &) = delete;
  MovieWriter &operator=(const MovieWriter &) = delete;

  // Queues a copy of `frame` (width x height as opened). See the header comment for a full
  // queue. OK, or once the error that stopped the movie.
  Status submit(const Frame &frame);
  MovieProgress progress() const;
  // Encodes what is queued, drains the encoder and completes the file (its index). Idempotent;
  // OK, or the error that stopped the movie.
  Status finish();

  const MovieConfig &config() const { return config_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  MovieWriter(const MovieConfig &movie, std::string path, int width, int height,
              std::unique_ptr<MovieEncoder> encoder);
  void run();  // the encoder thread

  struct Item {
    int64_t index = 0;  // the frame's place on the movie's clock
    std::vector<uint8_t> rgba;
  };

  const MovieConfig config_;
  const std::string path_;
  const int width_, height_;
  std::unique_ptr<MovieEncoder> encoder_;  // used by the encoder thread only, once started

  mutable std::mutex mutex_;
  std::condition_variable work_;   // a frame arrived, or stop
  std::condition_variable space_;  // the encoder took a frame
  std::deque<Item> queue_;
  std::vector<std::vector<uint8_t>> free_;  // buffers of encoded frames, reused
  bool stop_ = false;
  bool failed_ = false;
  bool error_reported_ = false;
  Status error_;  // what stopped the movie
  int64_t next_index_ = 0;
  int64_t written_ = 0;
  int64_t dropped_ = 0;
  double waited_ms_ = 0.0;
  double encode_ms_ = 0.0;
  bool finished_ = false;
  Status finish_status_;
  std::thread thread_;
};

}  // namespace lantern
