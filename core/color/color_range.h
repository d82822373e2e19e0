// The scalar range a scene's colours use, frame after frame (`color.range`): fixed ([min, max]),
// or automatic from each frame's scalar range, which the caller has reduced over every rank. With
// {auto: first} or {auto: running} the range remembers earlier frames, so that a colour means the
// same value in every frame of a movie. One per scene, kept between steps; not thread-safe.
#pragma once

#include <array>
#include <optional>

#include "core/config/config.h"

namespace lantern {

class ColorRange {
 public:
  // The range of this frame, given the frame's own (nullopt when no particle had a finite
  // scalar): config.range when fixed; else by config.auto_range the frame's range (frame), the
  // first range seen (first) or the union of all seen (running). nullopt while there is none.
  // A change of auto_range starts over.
  std::optional<std::array<double, 2>> update(const ColorConfig &config,
                                              const std::optional<std::array<double, 2>> &frame);
  // What the last update() returned.
  const std::optional<std::array<double, 2>> &current() const { return current_; }

 private:
  std::optional<std::array<double, 2>> resolve(const ColorConfig &config,
                                               const std::optional<std::array<double, 2>> &frame);
  std::optional<std::array<double, 2>> current_;
  AutoRange mode_ = AutoRange::kFrame;
  std::optional<std::array<double, 2>> kept_;
};

}  // namespace lantern
