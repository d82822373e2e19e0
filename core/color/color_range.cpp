#include "core/color/color_range.h"

#include <algorithm>

namespace lantern {

std::optional<std::array<double, 2>> ColorRange::update(
    const ColorConfig &config, const std::optional<std::array<double, 2>> &frame) {
  current_ = resolve(config, frame);
  return current_;
}

std::optional<std::array<double, 2>> ColorRange::resolve(
    const ColorConfig &config, const std::optional<std::array<double, 2>> &frame) {
  if (config.range) return config.range;
  if (config.auto_range != mode_) kept_.reset();
  mode_ = config.auto_range;
  switch (mode_) {
    case AutoRange::kFrame:
      return frame;
    case AutoRange::kFirst:
      if (!kept_) kept_ = frame;
      return kept_;
    case AutoRange::kRunning:
      if (frame)
        kept_ = kept_ ? std::array<double, 2>{std::min((*kept_)[0], (*frame)[0]),
                                              std::max((*kept_)[1], (*frame)[1])}
                      : *frame;
      return kept_;
  }
  return frame;
}

}  // namespace lantern
