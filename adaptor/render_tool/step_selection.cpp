#include "step_selection.h"

#include <charconv>
#include <sstream>

namespace lantern {
namespace {

bool parse_step(const std::string &s, int64_t *out) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *out);
  return !s.empty() && r.ec == std::errc() && r.ptr == s.data() + s.size();
}

std::string available(const std::vector<FrameInfo> &frames) {
  if (frames.empty()) return "no frames";
  return std::to_string(frames.size()) + " frames, steps " + std::to_string(frames.front().step) +
         ".." + std::to_string(frames.back().step);
}

}  // namespace

std::string select_frames(const std::string &option, const std::vector<FrameInfo> &frames,
                          std::vector<size_t> *out) {
  out->clear();
  if (option.empty()) {
    for (size_t i = 0; i < frames.size(); ++i) out->push_back(i);
    return {};
  }
  if (const size_t colon = option.find(':'); colon != std::string::npos) {
    int64_t a = 0, b = 0;
    if (!parse_step(option.substr(0, colon), &a) || !parse_step(option.substr(colon + 1), &b))
      return "--steps: '" + option + "' is not a range a:b of integers";
    for (size_t i = 0; i < frames.size(); ++i)
      if (frames[i].step >= a && frames[i].step <= b) out->push_back(i);
    if (out->empty())
      return "--steps: no frame in " + option + " (the input has " + available(frames) + ")";
    return {};
  }
  std::istringstream list(option);
  for (std::string item; std::getline(list, item, ',');) {
    int64_t step = 0;
    if (!parse_step(item, &step)) return "--steps: '" + item + "' is not an integer";
    size_t i = 0;
    while (i < frames.size() && frames[i].step != step) ++i;
    if (i == frames.size())
      return "--steps: step " + item + " is not in the input (it has " + available(frames) + ")";
    out->push_back(i);
  }
  return {};
}

}  // namespace lantern
