// The 256-entry RGB8 tables of the named colormaps, computed at compile time from the published
// definitions in colormap_data.h. Entry i is the map's colour at t = i / 255, rounded to the
// nearest byte: for a 256-colour list that is colour i itself; for control points (coolwarm,
// RdBu, seismic) it is the linear interpolation between the two points around t, the points
// evenly spaced over [0, 1] (as matplotlib samples them).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "core/color/colormap_data.h"

namespace lantern::colormap_tables {

using Table = std::array<std::array<uint8_t, 3>, 256>;

// [0, 1] to the nearest byte (clamped).
constexpr uint8_t to_byte(double v) {
  return static_cast<uint8_t>((v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v) * 255.0 + 0.5);
}

// A 256-colour list: colour i is entry i.
constexpr Table listed(const double (&colors)[256][3]) {
  Table t{};
  for (size_t i = 0; i < 256; ++i)
    for (size_t c = 0; c < 3; ++c) t[i][c] = to_byte(colors[i][c]);
  return t;
}

// Control point k of n at k / (n - 1), linear in between; `scale` divides the given values
// (255 for byte-valued sources).
template <typename T, size_t N>
constexpr Table segmented(const T (&points)[N][3], double scale = 1.0) {
  static_assert(N >= 2, "a colormap needs at least two control points");
  Table t{};
  for (size_t i = 0; i < 256; ++i) {
    const double position = (double(i) / 255.0) * double(N - 1);
    size_t k = static_cast<size_t>(position);
    if (k > N - 2) k = N - 2;
    const double f = position - double(k);
    for (size_t c = 0; c < 3; ++c) {
      const double a = double(points[k][c]) / scale, b = double(points[k + 1][c]) / scale;
      t[i][c] = to_byte(a + (b - a) * f);
    }
  }
  return t;
}

constexpr Table grayscale() {
  Table t{};
  for (size_t i = 0; i < 256; ++i) t[i] = {uint8_t(i), uint8_t(i), uint8_t(i)};
  return t;
}

inline constexpr Table kViridis = listed(colormap_data::kViridis);
inline constexpr Table kPlasma = listed(colormap_data::kPlasma);
inline constexpr Table kInferno = listed(colormap_data::kInferno);
inline constexpr Table kMagma = listed(colormap_data::kMagma);
inline constexpr Table kCividis = listed(colormap_data::kCividis);
inline constexpr Table kTurbo = listed(colormap_data::kTurbo);
inline constexpr Table kCoolwarm = segmented(colormap_data::kCoolwarm);
inline constexpr Table kRdBu = segmented(colormap_data::kRdBu, 255.0);
inline constexpr Table kSeismic = segmented(colormap_data::kSeismic);
inline constexpr Table kGrayscale = grayscale();

}  // namespace lantern::colormap_tables
