#include "core/color/colormap.h"

#include "core/color/colormap_tables.h"

namespace lantern {

Rgb8 to_rgb8(const std::array<double, 3> &rgb) {
  Rgb8 out{};
  for (int c = 0; c < 3; ++c) {
    const double v = rgb[c] < 0.0 ? 0.0 : (rgb[c] > 1.0 ? 1.0 : rgb[c]);
    out[c] = static_cast<uint8_t>(v * 255.0 + 0.5);
  }
  return out;
}

const std::vector<std::string> &Colormap::names() {
  static const std::vector<std::string> kNames = {"viridis", "plasma", "coolwarm", "grayscale"};
  return kNames;
}

std::optional<Colormap> Colormap::named(const std::string &name) {
  if (name == "viridis") return Colormap(&colormap_tables::kViridis);
  if (name == "plasma") return Colormap(&colormap_tables::kPlasma);
  if (name == "coolwarm") return Colormap(&colormap_tables::kCoolwarm);
  if (name == "grayscale") return Colormap(&colormap_tables::kGrayscale);
  return std::nullopt;
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
