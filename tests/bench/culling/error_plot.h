// An SVG plot of error against time: one panel per scene, x = median ms per frame (log scale),
// y = PSNR against brute force (bit-identical modes drawn on a separate "identical" line).
#pragma once

#include <string>
#include <vector>

namespace lantern::bench {

struct PlotPoint {
  std::string scene, mode;
  double ms = 0.0;
  double psnr = 0.0;  // +inf: identical
};

// Returns "" or an error message.
std::string write_error_plot(const std::string &path, const std::vector<PlotPoint> &points);

}  // namespace lantern::bench
