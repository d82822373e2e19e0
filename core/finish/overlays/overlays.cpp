#include "core/finish/overlays/overlays.h"

#include <utility>

#include "core/config/label_template.h"
#include "core/finish/overlays/axes_overlay.h"
#include "core/finish/overlays/overlay_canvas.h"
#include "core/finish/overlays/overlay_layout.h"

namespace lantern {

Status check_overlay_font(const OverlaySettings &settings) {
  if (!settings.has_text()) return {};
  std::string file;
  if (Status s = find_font_file(settings.font, &file); !s.ok()) return s;
  std::unique_ptr<FontFace> face;
  return FontFace::open(file, &face);
}

Status OverlayPainter::open(const OverlaySettings &settings, std::unique_ptr<OverlayPainter> *out) {
  auto painter = std::make_unique<OverlayPainter>();
  painter->font_request_ = settings.font;
  if (settings.has_text()) {
    std::string file;
    if (Status s = find_font_file(settings.font, &file); !s.ok()) return s;
    if (Status s = FontFace::open(file, &painter->font_); !s.ok()) return s;
  }
  *out = std::move(painter);
  return {};
}

bool OverlayPainter::serves(const OverlaySettings &settings) const {
  return settings.font == font_request_ && (font_ || !settings.has_text());
}

void OverlayPainter::draw(const OverlaySettings &settings, const OverlayFrame &frame,
                          Frame *image) {
  // The box first: it belongs to the scene (depth-tested); the text lies over everything.
  if (settings.box.enabled && frame.camera != nullptr)
    draw_box(settings.box, frame.box, *frame.camera, image);
  if (!font_) return;
  OverlayLayout layout(image->width, image->height);
  for (const LabelConfig &label : settings.labels) {
    const std::string text = expand_label(label.text, frame.step, frame.time, settings.scene_name);
    const TextMask mask = font_->render(text, label.size);
    const std::array<int, 2> at = layout.place(label.position, mask.width, mask.height);
    draw_mask(image, mask, at[0], at[1], to_rgb8(label.color));
  }
  if (settings.legend.enabled) {
    LegendColors colors = settings.legend_colors;
    colors.range = frame.range;
    colors.scalar_name = frame.scalar_name;
    draw_legend(settings.legend, colors, *font_, layout, image);
  }
  if (settings.axes.enabled && frame.camera != nullptr)
    draw_axes(settings.axes, *frame.camera, *font_, layout, image);
}

}  // namespace lantern
