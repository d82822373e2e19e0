// Cutting an H5MD file of Lantern's layout (h5md_layout.h) back to its complete frames, after a
// frame failed part-way (a full disk, an HDF5 error on one rank): every time series - value, step
// and time of each element - is shrunk to `frames` frames, and the particle axis of the
// per-particle values to `rows`, so value and step agree in length again and no frame of
// unwritten bytes (zeros) stays at the end.
//
// Serial: one process opens the closed file with HDF5's default (POSIX) driver. Shrinking a
// chunked dataset frees chunks, and in parallel HDF5 that left the ranks' ideas of the file's end
// apart, sending them into different collective calls at the next flush; done here by one
// process on the closed file, nothing can diverge. Not thread-safe (HDF5 is not, here).
#pragma once

#include <cstdint>
#include <string>

#include "core/common/status.h"

namespace lantern {

// OK, or kIo naming the file and the dataset that could not be shrunk.
Status cut_back_frames(const std::string &path, int64_t frames, int64_t rows);

}  // namespace lantern
