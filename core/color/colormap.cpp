#include "core/color/colormap.h"

#include <algorithm>
#include <utility>

#include "core/color/colormap_tables.h"

namespace lantern {

Rgb8 to_rgb8(const std::array<double, 3> &rgb) {
  Rgb8 out{};
  for (int c = 0; c < 3; ++c) out[c] = colormap_tables::to_byte(rgb[c]);
  return out;
}

namespace {

// The named maps in the order names() lists them.
const std::vector<std::pair<std::string, const colormap_tables::Table *>> &named_tables() {
  static const std::vector<std::pair<std::string, const colormap_tables::Table *>> kTables = {
      {"viridis", &colormap_tables::kViridis},   {"plasma", &colormap_tables::kPlasma},
      {"inferno", &colormap_tables::kInferno},   {"magma", &colormap_tables::kMagma},
      {"cividis", &colormap_tables::kCividis},   {"turbo", &colormap_tables::kTurbo},
      {"coolwarm", &colormap_tables::kCoolwarm}, {"RdBu", &colormap_tables::kRdBu},
      {"seismic", &colormap_tables::kSeismic},   {"grayscale", &colormap_tables::kGrayscale}};
  return kTables;
}

}  // namespace

const std::vector<std::string> &Colormap::names() {
  static const std::vector<std::string> kNames = [] {
    std::vector<std::string> names;
    for (const auto &entry : named_tables()) names.push_back(entry.first);
    return names;
  }();
  return kNames;
}

std::optional<Colormap> Colormap::named(const std::string &name) {
  for (const auto &[candidate, table] : named_tables())
    if (candidate == name) return Colormap(*table);
  return std::nullopt;
}

Colormap Colormap::from_colors(const std::vector<std::array<double, 3>> &colors) {
  Table table{};
  if (colors.empty()) return Colormap(table);
  if (colors.size() == 1) {
    table.fill(to_rgb8(colors[0]));
    return Colormap(table);
  }
  // The same sampling as colormap_tables::segmented, for a run-time list.
  const size_t n = colors.size();
  for (size_t i = 0; i < 256; ++i) {
    const double position = (double(i) / 255.0) * double(n - 1);
    const size_t k = std::min(static_cast<size_t>(position), n - 2);
    const double f = position - double(k);
    for (size_t c = 0; c < 3; ++c) {
      const double a = colors[k][c], b = colors[k + 1][c];
      table[i][c] = colormap_tables::to_byte(a + (b - a) * f);
    }
  }
  return Colormap(table);
}

Colormap Colormap::choose(const std::string &name, const std::vector<std::array<double, 3>> &colors,
                          bool reverse) {
  const Colormap map = colors.empty() ? named(name).value_or(Colormap(colormap_tables::kViridis))
                                      : from_colors(colors);
  return reverse ? map.reversed() : map;
}

Colormap Colormap::reversed() const {
  Table table = table_;
  std::reverse(table.begin(), table.end());
  return Colormap(table);
}

TypePalette::TypePalette(const std::vector<std::array<double, 3>> &custom) {
  // Okabe & Ito (2008): orange, sky blue, bluish green, yellow, blue, vermillion, reddish purple,
  // grey.
  static const std::vector<std::array<double, 3>> kBuiltIn = {
      {0.902, 0.624, 0.000}, {0.337, 0.706, 0.914}, {0.000, 0.620, 0.451}, {0.941, 0.894, 0.259},
      {0.000, 0.447, 0.698}, {0.835, 0.369, 0.000}, {0.800, 0.475, 0.655}, {0.600, 0.600, 0.600}};
  for (const auto &c : custom.empty() ? kBuiltIn : custom) colors_.push_back(to_rgb8(c));
}

}  // namespace lantern
