// A written image read back as a Frame (RGBA, 8 bits; alpha 255 where the file has none), for
// benches that compare the images a run wrote (image_metrics.h). Rows as the file stores them.
#pragma once

#include <string>

#include "core/view/frame.h"

namespace lantern::bench {

// An empty (0 x 0) frame where the file cannot be read.
Frame read_frame(const std::string &path);

}  // namespace lantern::bench
