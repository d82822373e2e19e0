// Overlays: what the picture shows, drawn on rank 0 over the finished image (after compositing,
// down-sampling and the screen-space cues, before the image file and the movie frame are
// written): the simulation box (depth-tested against the composited depth), text labels, the
// colour legend and the axis triad. Their inputs - the configuration, the camera, the step and
// time, the colour range reduced over the ranks, rank 0's box - are the same at any rank count,
// so the image stays byte-identical at any rank count and split.
//
// Ownership: an OverlayPainter owns its font (glyphs are cached between frames). Thread-safety:
// one thread at a time per painter. Never throws.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/camera/camera.h"
#include "core/common/status.h"
#include "core/config/config.h"
#include "core/finish/overlays/box_overlay.h"
#include "core/finish/overlays/font_face.h"
#include "core/finish/overlays/legend_overlay.h"
#include "core/view/frame.h"

namespace lantern {

// A scene's overlays, resolved once by the pipeline from its configuration.
struct OverlaySettings {
  std::string scene_name;           // {scene} in labels
  std::vector<LabelConfig> labels;  // labels
  LegendConfig legend;              // legend
  LegendColors legend_colors;       // the scene's colours (range and title filled per frame)
  BoxOverlayConfig box;             // box
  AxesConfig axes;                  // axes
  std::string font;                 // font: "" (DejaVu Sans), a family, or a file
  bool has_text() const { return !labels.empty() || legend.enabled || axes.enabled; }
  bool any() const { return has_text() || box.enabled; }
};

// What one frame's overlays read.
struct OverlayFrame {
  int64_t step = 0;
  double time = 0.0;
  std::optional<std::array<double, 2>> range;  // the colours' scalar range this frame
  std::string scalar_name;                     // the colour bar's default title
  BoxCorners box;                              // the simulation box
  const Camera *camera = nullptr;              // the scene's camera (its frustum)
};

// Local: the font a scene's text needs exists and FreeType reads it; kConfig naming what was
// looked for, or saying the build has no text. OK when `settings` has no text.
Status check_overlay_font(const OverlaySettings &settings);

class OverlayPainter {
 public:
  // A painter for `settings` (its font opened when it has text). Errors as check_overlay_font.
  static Status open(const OverlaySettings &settings, std::unique_ptr<OverlayPainter> *out);
  // Whether this painter serves `settings` (the same font, and text if it needs text).
  bool serves(const OverlaySettings &settings) const;
  // Draws the overlays on `image` (width x height, with the composited depth, on rank 0).
  void draw(const OverlaySettings &settings, const OverlayFrame &frame, Frame *image);

 private:
  std::string font_request_;
  std::unique_ptr<FontFace> font_;  // null without text
};

}  // namespace lantern
