#include "core/output/background_image_writer.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <memory>
#include <system_error>
#include <thread>

#include "core/output/atomic_file.h"

namespace lantern {
namespace {

Status check_writable_directory(const std::string &path) {
  if (Status s = create_parent_directories(path); !s.ok()) return s;
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  if (::access(dir.c_str(), W_OK) != 0)
    return {StatusCode::kIo, "cannot write into '" + dir.string() + "': " + std::strerror(errno)};
  return {};
}

}  // namespace

BackgroundImageWriter::~BackgroundImageWriter() {
  wait();
}

Status BackgroundImageWriter::wait() {
  if (!in_flight_.valid()) return {};
  return in_flight_.get();
}

Status BackgroundImageWriter::submit(Frame frame, const OutputConfig &out, const std::string &path,
                                     DepthToDistance depth_to_distance, Frame *spare) {
  const Status error = check_writable_directory(path);
  Status previous = wait();
  if (spare) *spare = written_ ? std::move(*written_) : Frame();
  written_.reset();
  if (!error.ok()) {
    if (previous.ok()) return error;
    previous.message += "; " + error.message;  // both failures, under the earlier one's code
    return previous;
  }
  // Shared so that the task stays here if no thread can be started.
  // The frame goes back to written_ when the image is written (before the future is ready).
  auto written = std::make_shared<Frame>();
  auto task = std::make_shared<std::packaged_task<Status()>>(
      [frame = std::move(frame), out, path, to_distance = std::move(depth_to_distance),
       written]() mutable -> Status {
        Status status;
        try {
          status = write_image(frame, out, path, to_distance);
        } catch (const std::exception &e) {
          status = {StatusCode::kIo, "writing '" + path + "': " + e.what()};
        }
        *written = std::move(frame);
        return status;
      });
  written_ = std::move(written);
  in_flight_ = task->get_future();
  try {
    std::thread([task] { (*task)(); }).detach();
  } catch (const std::system_error &) {
    (*task)();  // no thread to be had: write now rather than not at all
  }
  return previous;
}

}  // namespace lantern
