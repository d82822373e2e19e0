#include "error_plot.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace lantern::bench {
namespace {

constexpr double kPanelW = 760, kPanelH = 300, kLeft = 70, kRight = 20, kTop = 36, kBottom = 44;
constexpr double kPsnrMin = 10, kPsnrMax = 60;  // finite PSNR axis; identical drawn above it

std::string escape(const std::string &s) {
  std::string o;
  for (char c : s)
    o += c == '<' ? std::string("&lt;") : c == '&' ? std::string("&amp;") : std::string(1, c);
  return o;
}

}  // namespace

std::string write_error_plot(const std::string &path, const std::vector<PlotPoint> &points) {
  std::vector<std::string> scenes;
  for (const PlotPoint &p : points)
    if (std::find(scenes.begin(), scenes.end(), p.scene) == scenes.end()) scenes.push_back(p.scene);
  std::ostringstream svg;
  const double height = kPanelH * double(scenes.size());
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << kPanelW << "' height='" << height
      << "' font-family='sans-serif' font-size='11'>\n<rect width='100%' height='100%' "
         "fill='white'/>\n";
  for (size_t s = 0; s < scenes.size(); ++s) {
    const double y0 = kPanelH * double(s);
    double lo = 1e300, hi = 0;
    for (const PlotPoint &p : points)
      if (p.scene == scenes[s]) lo = std::min(lo, p.ms), hi = std::max(hi, p.ms);
    const double l0 = std::floor(std::log10(std::max(lo, 1e-3))),
                 l1 = std::ceil(std::log10(std::max(hi, 1e-3)) + 1e-9);
    const double pw = kPanelW - kLeft - kRight, ph = kPanelH - kTop - kBottom;
    const auto px = [&](double ms) { return kLeft + (std::log10(ms) - l0) / (l1 - l0) * pw; };
    const auto py = [&](double psnr) {
      if (std::isinf(psnr)) return y0 + kTop - 12;
      const double c = std::clamp(psnr, kPsnrMin, kPsnrMax);
      return y0 + kTop + (kPsnrMax - c) / (kPsnrMax - kPsnrMin) * ph;
    };
    svg << "<text x='" << kLeft << "' y='" << y0 + 16 << "' font-size='13' font-weight='bold'>"
        << escape(scenes[s]) << ": error against time</text>\n";
    svg << "<rect x='" << kLeft << "' y='" << y0 + kTop << "' width='" << pw << "' height='" << ph
        << "' fill='none' stroke='black'/>\n";
    for (double l = l0; l <= l1 + 1e-9; l += 1) {
      const double x = px(std::pow(10.0, l));
      svg << "<line x1='" << x << "' y1='" << y0 + kTop << "' x2='" << x << "' y2='"
          << y0 + kTop + ph << "' stroke='#ddd'/><text x='" << x - 10 << "' y='"
          << y0 + kTop + ph + 14 << "'>" << std::pow(10.0, l) << "</text>\n";
    }
    for (double v = kPsnrMin; v <= kPsnrMax; v += 10)
      svg << "<text x='" << kLeft - 30 << "' y='" << py(v) + 4 << "'>" << v << "</text>\n";
    svg << "<text x='" << kLeft - 66 << "' y='" << py(INFINITY) + 4 << "'>identical</text>\n";
    svg << "<text x='" << kLeft + pw / 2 - 60 << "' y='" << y0 + kPanelH - 8
        << "'>median ms per frame (log)</text>\n";
    svg << "<text transform='translate(" << 14 << "," << y0 + kTop + ph / 2 + 40
        << ") rotate(-90)'>PSNR vs brute force, dB</text>\n";
    for (const PlotPoint &p : points) {
      if (p.scene != scenes[s]) continue;
      const bool exact = std::isinf(p.psnr);
      svg << "<circle cx='" << px(p.ms) << "' cy='" << py(p.psnr) << "' r='4' fill='"
          << (exact ? "#1a7f37" : "#cf222e") << "'/><text x='" << px(p.ms) + 6 << "' y='"
          << py(p.psnr) - 5 << "'>" << escape(p.mode) << "</text>\n";
    }
  }
  svg << "</svg>\n";
  std::ofstream out(path);
  out << svg.str();
  out.close();  // the write reaches the file (or fails) here
  return out ? "" : "cannot write " + path;
}

}  // namespace lantern::bench
