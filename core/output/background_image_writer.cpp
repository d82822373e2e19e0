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

std::string check_writable_directory(const std::string &path) {
  if (auto e = create_parent_directories(path); !e.empty()) return e;
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  if (::access(dir.c_str(), W_OK) != 0)
    return "cannot write into '" + dir.string() + "': " + std::strerror(errno);
  return {};
}

}  // namespace

BackgroundImageWriter::~BackgroundImageWriter() {
  wait();
}

std::string BackgroundImageWriter::wait() {
  if (!in_flight_.valid()) return {};
  return in_flight_.get();
}

std::string BackgroundImageWriter::submit(Frame frame, const OutputConfig &out,
                                          const std::string &path,
                                          DepthToDistance depth_to_distance) {
  const std::string error = check_writable_directory(path);
  const std::string previous = wait();
  if (!error.empty()) return previous.empty() ? error : previous + "; " + error;
  // Shared so that the task stays here if no thread can be started.
  auto task = std::make_shared<std::packaged_task<std::string()>>(
      [frame = std::move(frame), out, path,
       to_distance = std::move(depth_to_distance)]() -> std::string {
        try {
          return write_image(frame, out, path, to_distance);
        } catch (const std::exception &e) {
          return "writing '" + path + "': " + e.what();
        }
      });
  in_flight_ = task->get_future();
  try {
    std::thread([task] { (*task)(); }).detach();
  } catch (const std::system_error &) {
    (*task)();  // no thread to be had: write now rather than not at all
  }
  return previous;
}

}  // namespace lantern
