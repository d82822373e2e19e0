#include "core/finish/overlays/legend_overlay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/color/colormap.h"
#include "core/finish/overlays/overlay_canvas.h"

namespace lantern {
namespace {

// Heckbert's nice number: 1, 2, 5 or 10 times a power of ten, near x (rounded or above it).
double nice_number(double x, bool round) {
  const double exponent = std::floor(std::log10(x));
  const double fraction = x / std::pow(10.0, exponent);
  double nice;
  if (round)
    nice = fraction < 1.5 ? 1 : fraction < 3 ? 2 : fraction < 7 ? 5 : 10;
  else
    nice = fraction <= 1 ? 1 : fraction <= 2 ? 2 : fraction <= 5 ? 5 : 10;
  return nice * std::pow(10.0, exponent);
}

// An outline one pixel outside the rectangle [x, x + w) x [y, y + h).
void frame_rect(Frame *image, int x, int y, int w, int h, const Rgb8 &color) {
  fill_rect(image, x - 1, y - 1, w + 2, 1, color);
  fill_rect(image, x - 1, y + h, w + 2, 1, color);
  fill_rect(image, x - 1, y, 1, h, color);
  fill_rect(image, x + w, y, 1, h, color);
}

std::string end_text(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.4g", value);
  return buffer;
}

LegendBar draw_color_bar(const LegendConfig &legend, const LegendColors &colors, FontFace &font,
                         OverlayLayout &layout, Frame *image) {
  const Rgb8 ink = to_rgb8(legend.color);
  const int fs = legend.font_size;
  const int length = legend.length.value_or(std::max(16, int(std::lround(0.4 * image->height))));
  const int width = legend.width;
  const int tick = std::max(3, width / 3), gap = std::max(2, fs / 4);
  const std::string title = legend.title.value_or(colors.scalar_name);
  const TextMask title_mask = title.empty() ? TextMask() : font.render(title, fs);

  // The labelled values: the range's ends, and round values between them that keep a label's
  // height clear of their neighbours.
  struct Tick {
    double value;
    TextMask text;
  };
  std::vector<Tick> ticks;
  if (colors.range) {
    const double lo = (*colors.range)[0], hi = (*colors.range)[1];
    ticks.push_back({hi, font.render(end_text(hi), fs)});
    const std::vector<double> inner = nice_ticks(lo, hi, legend.ticks);
    const double step = inner.size() > 1 ? inner[1] - inner[0] : hi - lo;
    const int label_height = ticks.front().text.height;
    for (auto v = inner.rbegin(); v != inner.rend(); ++v) {
      const double from_ends = std::min(hi - *v, *v - lo) / (hi - lo) * (length - 1);
      if (from_ends >= label_height) ticks.push_back({*v, font.render(tick_text(*v, step), fs)});
    }
    if (hi > lo) ticks.push_back({lo, font.render(end_text(lo), fs)});
  }
  int label_width = 0, label_height = 0;
  for (const Tick &t : ticks) {
    label_width = std::max(label_width, t.text.width);
    label_height = std::max(label_height, t.text.height);
  }
  const int title_height = title_mask.height > 0 ? title_mask.height + gap : 0;
  const int pad = (label_height + 1) / 2;  // the end labels reach half their height past the bar
  const int total_w = std::max(title_mask.width, width + 1 + tick + gap + label_width);
  const int total_h = title_height + std::max(pad, 1) + length + std::max(pad, 1);
  const std::array<int, 2> at = layout.place(legend.position, total_w, total_h);

  if (title_mask.width > 0) draw_mask(image, title_mask, at[0], at[1], ink);
  LegendBar bar{at[0] + 1, at[1] + title_height + std::max(pad, 1), width, length};
  // The colormap's table, as the spheres used it: row 0 is its high end, the last row its low.
  const Colormap map = Colormap::choose(colors.colormap, colors.colormap_colors, colors.reverse);
  for (int r = 0; r < length; ++r) {
    const long entry =
        length > 1 ? std::lround(double(length - 1 - r) * 255.0 / (length - 1)) : 255;
    fill_rect(image, bar.x, bar.y + r, width, 1, map.table()[size_t(entry)]);
  }
  frame_rect(image, bar.x, bar.y, width, length, ink);
  if (colors.range) {
    const double lo = (*colors.range)[0], hi = (*colors.range)[1];
    for (const Tick &t : ticks) {
      // (hi - value) / (hi - lo), bit for bit (negation is exact), safe where hi - lo overflows.
      const double share = hi > lo ? Colormap::range_fraction(-t.value, -hi, -lo) : 0.0;
      const int row = bar.y + int(std::lround(share * (length - 1)));
      fill_rect(image, bar.x + width + 1, row, tick, 1, ink);
      draw_mask(image, t.text, bar.x + width + 1 + tick + gap, row - t.text.height / 2, ink);
    }
  }
  return bar;
}

void draw_type_key(const LegendConfig &legend, const LegendColors &colors, FontFace &font,
                   OverlayLayout &layout, Frame *image) {
  const Rgb8 ink = to_rgb8(legend.color);
  const int fs = legend.font_size, gap = std::max(2, fs / 3);
  const TextMask title_mask = legend.title ? font.render(*legend.title, fs) : TextMask();
  std::vector<TextMask> names;
  int names_width = 0, row_height = legend.width;
  for (const std::string &name : legend.type_names) {
    names.push_back(font.render(name, fs));
    names_width = std::max(names_width, names.back().width);
    row_height = std::max(row_height, names.back().height);
  }
  const int title_height = title_mask.height > 0 ? title_mask.height + gap : 0;
  const int rows = int(names.size());
  const int total_w = std::max(title_mask.width, 2 + legend.width + gap + names_width);
  const int total_h = title_height + rows * row_height + (rows - 1) * gap;
  const std::array<int, 2> at = layout.place(legend.position, total_w, total_h);
  if (title_mask.width > 0) draw_mask(image, title_mask, at[0], at[1], ink);
  const TypePalette palette(colors.palette);
  for (int i = 0; i < rows; ++i) {
    const int y = at[1] + title_height + i * (row_height + gap);
    const int swatch_y = y + (row_height - legend.width) / 2;
    fill_rect(image, at[0] + 1, swatch_y, legend.width, legend.width, palette.at(i));
    frame_rect(image, at[0] + 1, swatch_y, legend.width, legend.width, ink);
    draw_mask(image, names[size_t(i)], at[0] + 2 + legend.width + gap,
              y + (row_height - names[size_t(i)].height) / 2, ink);
  }
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int count) {
  std::vector<double> ticks;
  if (!(lo < hi) || !std::isfinite(lo) || !std::isfinite(hi) || count < 1) return ticks;
  const double step = nice_number(nice_number(hi - lo, false) / count, true);
  if (!(step > 0) || !std::isfinite(step)) return ticks;
  // Counted in steps from the first multiple, at most 101 of them (far beyond any count asked
  // for): where lo / step is 2^53 or more (a range a few ulps wide, as an almost constant field
  // gives), adding 1 to the multiple leaves it unchanged, and a loop over it never ended.
  const double first = std::ceil(lo / step);
  for (int i = 0; i <= 100; ++i) {
    const double v = (first + i) * step;
    if (!(v < hi)) break;
    if (v > lo && (ticks.empty() || v > ticks.back()))
      ticks.push_back(std::abs(v) < step * 1e-9 ? 0.0 : v);
  }
  return ticks;
}

std::string tick_text(double value, double step) {
  char buffer[64];
  const double magnitude = std::max(std::abs(value), std::abs(step));
  if (!(step > 0) || magnitude >= 1e6 || magnitude < 1e-4) {
    std::snprintf(buffer, sizeof buffer, "%.3g", value);
    return buffer;
  }
  const int decimals = std::clamp(int(-std::floor(std::log10(step) + 1e-9)), 0, 10);
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

LegendBar draw_legend(const LegendConfig &legend, const LegendColors &colors, FontFace &font,
                      OverlayLayout &layout, Frame *image) {
  if (colors.by == ColorBy::kScalar) return draw_color_bar(legend, colors, font, layout, image);
  draw_type_key(legend, colors, font, layout, image);
  return {};
}

}  // namespace lantern
