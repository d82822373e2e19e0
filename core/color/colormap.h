// Scalar -> color through a named colormap, and integer type -> color through a palette.
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

class Colormap {
 public:
  // "viridis", "plasma", "coolwarm", "grayscale"; std::nullopt for an unknown name.
  static std::optional<Colormap> named(const std::string &name);
  static const std::vector<std::string> &names();

  // Maps value in [lo, hi] linearly onto the map; values outside clamp to the ends. A NaN value
  // or an empty range (lo >= hi) maps to the middle of the map.
  Rgb8 at(double value, double lo, double hi) const {
    double t = 0.5;
    if (hi > lo && !std::isnan(value)) t = (value - lo) / (hi - lo);
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    return (*table_)[static_cast<size_t>(t * 255.0 + 0.5)];
  }

 private:
  explicit Colormap(const std::array<Rgb8, 256> *table) : table_(table) {}
  const std::array<Rgb8, 256> *table_;
};

// Color of an integer particle type: palette[type mod size] (negative types wrap too). An empty
// palette uses the built-in one (Okabe-Ito colors, distinguishable with color blindness).
class TypePalette {
 public:
  explicit TypePalette(const std::vector<std::array<double, 3>> &custom);
  Rgb8 at(int64_t type) const {
    const auto n = static_cast<int64_t>(colors_.size());
    return colors_[static_cast<size_t>(((type % n) + n) % n)];
  }

 private:
  std::vector<Rgb8> colors_;
};

}  // namespace lantern
