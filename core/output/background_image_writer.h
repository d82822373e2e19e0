// Writes images on a background thread, so that a simulation step does not wait for image
// encoding (PNG compression of a 1-2 megapixel frame costs 100-300 ms, often more than culling
// and drawing a million particles together).
//
// One image in flight at a time: submit() first waits for the previous image, so memory stays
// bounded at one extra frame and errors surface at most one scheduled step late. What can be
// checked at once is checked at once: a directory that cannot be created or written fails the
// step that asked for it. The thread only encodes, writes the temporary file and renames it
// (atomic_file.h), so a crash still never leaves a truncated image.
//
// Thread-safety: one owner thread calls submit()/wait(); the writer thread touches only the
// frame it was given. The destructor waits for the image in flight.
#pragma once

#include <future>
#include <memory>
#include <string>

#include "core/common/status.h"
#include "core/output/image_writer.h"

namespace lantern {

class BackgroundImageWriter {
 public:
  BackgroundImageWriter() = default;
  ~BackgroundImageWriter();
  BackgroundImageWriter(BackgroundImageWriter &&) = default;
  BackgroundImageWriter(const BackgroundImageWriter &) = delete;
  BackgroundImageWriter &operator=(const BackgroundImageWriter &) = delete;

  // Checks that `path`'s directory exists (creating it) and is writable, waits for the previous
  // image, then writes `frame` (taken over) to `path` in the background. Returns OK or the error
  // of the check (kIo) or of the previous image (write_image's status, which names its own path).
  // `spare`, where not null, receives the previous image's frame once it is written (an empty
  // Frame when there was none), so that the caller renders the next image into its buffers
  // rather than into freshly allocated pages every step.
  Status submit(Frame frame, const OutputConfig &out, const std::string &path,
                DepthToDistance depth_to_distance, Frame *spare = nullptr);

  // Waits for the image in flight. OK or its write_image status.
  Status wait();

 private:
  std::future<Status> in_flight_;
  std::shared_ptr<Frame> written_;  // the image in flight's frame, once the writer is done with it
};

}  // namespace lantern
