// Scalar -> color through a colormap, and integer type -> color through a palette.
// Thread-safety: immutable after construction. Colors are RGB8.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace lantern {

using Rgb8 = std::array<uint8_t, 3>;

// Converts [r, g, b] in [0, 1] to RGB8 (rounded, clamped).
Rgb8 to_rgb8(const std::array<double, 3> &rgb);

// A 256-entry table: entry i is the map's colour at t = i / 255. Named maps come from their
// published definitions (colormap_data.h); a custom map from control points.
class Colormap {
 public:
  using Table = std::array<Rgb8, 256>;

  // One of names(); std::nullopt for an unknown name.
  static std::optional<Colormap> named(const std::string &name);
  // viridis, plasma, inferno, magma, cividis (perceptually uniform), turbo (rainbow), coolwarm,
  // RdBu, seismic (diverging), grayscale.
  static const std::vector<std::string> &names();
  // Control points in [0, 1] (at least two), evenly spaced over the map and interpolated
  // linearly in sRGB, as matplotlib's ListedColormap / from_list do; 256 points are the table.
  static Colormap from_colors(const std::vector<std::array<double, 3>> &colors);

  // A scene's map: colors (control points) when not empty, else the named map (viridis for an
  // unknown name); run backwards when `reverse`.
  static Colormap choose(const std::string &name, const std::vector<std::array<double, 3>> &colors,
                         bool reverse);

  // The same map run backwards (high values get the low end's colour).
  Colormap reversed() const;
  const Table &table() const { return table_; }

  // Maps value in [lo, hi] linearly onto the map; values outside clamp to the ends. A NaN value
  // or an empty range (lo >= hi) maps to the middle of the map.
  Rgb8 at(double value, double lo, double hi) const {
    double t = 0.5;
    if (hi > lo && !std::isnan(value)) t = range_fraction(value, lo, hi);
    // NaN cannot come out of range_fraction; were it to, it would go to the low end rather than
    // through the conversion to an index.
    t = t > 0.0 ? (t < 1.0 ? t : 1.0) : 0.0;
    return table_[static_cast<size_t>(t * 255.0 + 0.5)];
  }

  // (value - lo) / (hi - lo) for hi > lo, also where hi - lo overflows (a range like
  // [-1e308, 1e308], which "missing value" sentinels in a scalar field give): then in halves,
  // instead of inf / inf = NaN for the top value and 0 for every other.
  static double range_fraction(double value, double lo, double hi) {
    const double width = hi - lo;
    if (std::isfinite(width)) return (value - lo) / width;
    return (0.5 * value - 0.5 * lo) / (0.5 * hi - 0.5 * lo);
  }

 private:
  explicit Colormap(const Table &table) : table_(table) {}
  Table table_;
};

// Color of an integer particle type: palette[type mod size] (negative types wrap too). An empty
// palette uses the built-in one (Okabe-Ito colors, distinguishable with color blindness).
class TypePalette {
 public:
  explicit TypePalette(const std::vector<std::array<double, 3>> &custom);
  Rgb8 at(int64_t type) const {
    // Types within the palette skip the two 64-bit divisions: the CPU raster colours every
    // sphere it draws through here.
    if (static_cast<uint64_t>(type) < colors_.size()) return colors_[static_cast<size_t>(type)];
    const auto n = static_cast<int64_t>(colors_.size());  // never 0: the built-in palette else
    // cppcheck-suppress [zerodivcond,containerOutOfBounds] ; n > 0 and the index is in [0, n)
    return colors_[static_cast<size_t>(((type % n) + n) % n)];
  }

 private:
  std::vector<Rgb8> colors_;
};

}  // namespace lantern
