// libFuzzer: the LAMMPS text-dump reader (LammpsDumpReader) on any bytes: open() indexes the
// file, then every frame is read in two halves, as two ranks would. The bytes are handed over as
// an in-memory file (memfd), so nothing touches the disk.
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "core/dump/lammps_dump_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const int fd = memfd_create("lammps_dump", MFD_CLOEXEC);
  if (fd < 0) return 0;
  size_t written = 0;
  while (written < size) {
    const ssize_t n = write(fd, data + written, size - written);
    if (n <= 0) break;
    written += size_t(n);
  }
  const std::string path = "/proc/self/fd/" + std::to_string(fd);
  std::unique_ptr<lantern::LammpsDumpReader> reader;
  if (lantern::LammpsDumpReader::open(path, &reader).ok()) {
    const auto &frames = reader->frames();
    for (size_t f = 0; f < frames.size() && f < 8; ++f) {
      const int64_t count = frames[f].count, half = count / 2;
      lantern::ParticleFrame frame;
      if (reader->read(f, 0, half, &frame).ok() && frame.count() > half) __builtin_trap();
      if (reader->read(f, half, count, &frame).ok() && frame.count() > count - half)
        __builtin_trap();
    }
    lantern::ParticleFrame none;
    if (reader->read(frames.size(), 0, 1, &none).ok()) __builtin_trap();  // no such frame
  }
  close(fd);
  return 0;
}
