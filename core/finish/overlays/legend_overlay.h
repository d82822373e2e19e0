// legend: what the colours mean. For color.by: scalar a colour bar - the scene's colormap (the
// very table the spheres were shaded with), its high end at the top - with the frame's range
// written at its ends, evenly spaced round values between (Heckbert, "Nice numbers for graph
// labels", Graphics Gems, 1990) and a title (default: the scalar's name). For color.by: type a
// key: one swatch of the type palette's colour and one name per entry of type_names.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/finish/overlays/font_face.h"
#include "core/finish/overlays/overlay_layout.h"
#include "core/view/frame.h"

namespace lantern {

// What a legend shows of its scene's colours.
struct LegendColors {
  ColorBy by = ColorBy::kType;
  std::string colormap;  // by scalar: the map's name and custom colours, and reverse
  std::vector<std::array<double, 3>> colormap_colors;
  bool reverse = false;
  std::vector<std::array<double, 3>> palette;  // by type: the palette (empty = built-in)
  std::optional<std::array<double, 2>> range;  // by scalar: this frame's range (none: no data)
  std::string scalar_name;                     // the default title of a colour bar
};

// Round values strictly inside (lo, hi): about `count` intervals of 1, 2 or 5 times a power of
// ten. Empty when lo >= hi or either is not finite.
std::vector<double> nice_ticks(double lo, double hi, int count);

// The legend's text for a tick value, with as many decimals as the tick spacing `step` needs.
std::string tick_text(double value, double step);

// The bar's geometry on the image, once drawn (for tests and callers that place other things).
struct LegendBar {
  int x = 0, y = 0, width = 0, length = 0;  // the coloured bar's pixels, top-left and size
};

// Draws the legend on `image`. Returns where the colour bar went (width 0 for a type key).
LegendBar draw_legend(const LegendConfig &legend, const LegendColors &colors, FontFace &font,
                      OverlayLayout &layout, Frame *image);

}  // namespace lantern
