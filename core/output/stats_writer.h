// Per-step statistics as JSON lines: one JSON object per line, appended to a file.
//
// Each append() formats the whole line first and hands it to the OS in one write() on a file
// opened with O_APPEND, so lines are never interleaved or half-written by concurrent appenders
// (up to the OS's atomic append size) and a reader can tail the file while the run goes on. A write
// cut short (a full disk) is truncated back to the start of its line, and a line left incomplete
// by a process killed while writing it is cut off when the file is next opened for appending
// (before the new line, which would otherwise continue it): a line is in the file whole or not at
// all.
// A StatsWriter is not thread-safe; use one per writing thread (normally rank 0 only).
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "core/common/status.h"

namespace lantern {

class StatsWriter {
 public:
  // Does not touch the file system yet: the file (and its directories) are created on the first
  // append(), so a bad path surfaces as an append() error on a scheduled step.
  explicit StatsWriter(std::string path) : path_(std::move(path)) {}
  ~StatsWriter();
  StatsWriter(const StatsWriter &) = delete;
  StatsWriter &operator=(const StatsWriter &) = delete;

  // Appends `record` as one line and flushes it to the OS. OK, or kIo with a message naming the
  // file and the OS reason (kInternal if the record cannot be formatted); after a failure the
  // next call tries to open the file again.
  Status append(const nlohmann::json &record);

  // Closes the file (the next append opens it again): OK, or kIo where the OS reports a write
  // error only now (a network file system's quota or full disk).
  Status close();

  const std::string &path() const { return path_; }

 private:
  Status cut_incomplete_last_line();
  Status fail(const char *what, int reason, const std::string &more = "");

  std::string path_;
  int fd_ = -1;  // owned; -1 = not open
};

// One-shot form: opens, appends one line, closes.
Status append_json_line(const std::string &path, const nlohmann::json &record);

}  // namespace lantern
