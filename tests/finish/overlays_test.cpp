// Overlays (core/finish/overlays/) on plain frames: a label's text changes pixels only inside
// its rectangle, and is antialiased; the legend's bar ends are the colormap's ends and the key's
// swatches the palette's colours; the box's edges fall where the camera projects them and hide
// behind nearer depth. Text needs the build's FreeType and a font (DejaVu Sans through
// fontconfig); without text the tests that need it check the configuration error instead.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include "core/camera/camera.h"
#include "core/color/colormap.h"
#include "core/config/label_template.h"
#include "core/finish/overlays/box_overlay.h"
#include "core/finish/overlays/font_face.h"
#include "core/finish/overlays/legend_overlay.h"
#include "core/finish/overlays/overlay_canvas.h"
#include "core/finish/overlays/overlay_layout.h"
#include "core/finish/overlays/overlays.h"
#include "tests/support/orthographic_camera.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {
namespace {

constexpr uint8_t kWhite[4] = {255, 255, 255, 255};

Frame white_frame(int w, int h) {
  Frame f(w, h);
  f.clear(kWhite);
  return f;
}

std::array<uint8_t, 4> pixel(const Frame &f, int x, int y) {
  const uint8_t *p = f.rgba.data() + 4 * f.index(x, y);
  return {p[0], p[1], p[2], p[3]};
}

std::unique_ptr<FontFace> default_font() {
  std::string file;
  if (!find_font_file("", &file).ok()) return nullptr;
  std::unique_ptr<FontFace> face;
  if (!FontFace::open(file, &face).ok()) return nullptr;
  return face;
}

#define REQUIRE_TEXT()                                                     \
  if (!text_available()) GTEST_SKIP() << "this build has no overlay text"; \
  std::unique_ptr<FontFace> font = default_font();                         \
  ASSERT_NE(font, nullptr) << "DejaVu Sans not found through fontconfig"

TEST(LabelTemplate, ExpandsStepTimeAndScene) {
  EXPECT_EQ(expand_label("step {step:06d} t={time:.2f} {scene}", 42, 1.23456, "a"),
            "step 000042 t=1.23 a");
  EXPECT_EQ(expand_label("{step} {time} {{x}}", 7, 0.5, ""), "7 0.5 {x}");
  EXPECT_EQ(expand_label("{time:8.3e}", 0, 12345.0, ""), "1.234e+04");
  EXPECT_EQ(expand_label("{time:.0f}|{step:5d}", 3, 2.6, ""), "3|    3");
  // Fixed notation of a huge time: every digit (the buffer cut 1e200 to 127 digits, 1e126).
  const std::string huge = expand_label("{time:.2f}", 0, 1e200, "");
  EXPECT_EQ(huge.size(), 200u + 3u) << huge;  // the double nearest 1e200 is 9.99...e199
  EXPECT_EQ(huge.substr(huge.size() - 3), ".00");
  EXPECT_OK(validate_label_template("t = {time:.2f} ps"));
  EXPECT_EQ(validate_label_template("{temp}").code, StatusCode::kConfig);
  EXPECT_EQ(validate_label_template("{step:.2f}").code, StatusCode::kConfig);
  EXPECT_EQ(validate_label_template("{time:d}").code, StatusCode::kConfig);
  EXPECT_EQ(validate_label_template("{scene:5}").code, StatusCode::kConfig);
  EXPECT_EQ(validate_label_template("open {").code, StatusCode::kConfig);
}

TEST(FontFace, MissingFontsAreConfigErrorsNamingWhatWasLookedFor) {
  std::string file;
  Status s = find_font_file("/nonexistent/Font.ttf", &file);
  EXPECT_EQ(s.code, StatusCode::kConfig);
  if (!text_available()) {
    EXPECT_NE(s.message.find("LANTERN_WITH_TEXT"), std::string::npos) << s.message;
    return;
  }
  EXPECT_NE(s.message.find("/nonexistent/Font.ttf"), std::string::npos) << s.message;
  s = find_font_file("No Such Family Zzyzx", &file);
  EXPECT_EQ(s.code, StatusCode::kConfig);
  EXPECT_NE(s.message.find("No Such Family Zzyzx"), std::string::npos) << s.message;
  // A file that is not a font.
  std::unique_ptr<FontFace> face;
  s = FontFace::open("/etc/hostname", &face);
  EXPECT_EQ(s.code, StatusCode::kConfig);
  EXPECT_NE(s.message.find("/etc/hostname"), std::string::npos) << s.message;
}

// The label's pixels: changed inside the text's rectangle only, dark (black text), with partial
// coverage at the glyphs' edges (antialiased), and the same for a template and its expansion.
TEST(Overlays, LabelDarkensPixelsOnlyInsideItsRectangle) {
  REQUIRE_TEXT();
  OverlaySettings settings;
  settings.scene_name = "demo";
  LabelConfig label;
  label.text = "step {step}";
  label.position.at = std::array<int, 2>{40, 30};
  label.size = 24;
  settings.labels = {label};
  std::unique_ptr<OverlayPainter> painter;
  ASSERT_OK(OverlayPainter::open(settings, &painter));
  Frame image = white_frame(240, 120);
  OverlayFrame frame;
  frame.step = 1234;
  painter->draw(settings, frame, &image);

  const TextMask mask = font->render("step 1234", 24);
  ASSERT_GT(mask.width, 60);
  ASSERT_GT(mask.height, 15);
  int dark = 0, partial = 0, outside_changed = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const auto p = pixel(image, x, y);
      const bool inside = x >= 40 && x < 40 + mask.width && y >= 30 && y < 30 + mask.height;
      const bool changed = p[0] != 255 || p[1] != 255 || p[2] != 255;
      if (!inside) outside_changed += changed;
      if (inside && p[0] < 64) ++dark;
      if (inside && p[0] > 16 && p[0] < 240) ++partial;
      EXPECT_EQ(p[0], p[1]);  // black over white stays grey
      EXPECT_EQ(p[3], 255);
    }
  EXPECT_EQ(outside_changed, 0);
  EXPECT_GT(dark, 100);    // the strokes of nine characters at 24 pixels
  EXPECT_GT(partial, 40);  // antialiased edges
  // The template's field is the number: the same pixels as the literal text.
  Frame literal = white_frame(240, 120);
  settings.labels[0].text = "step 1234";
  painter->draw(settings, frame, &literal);
  EXPECT_EQ(literal.rgba, image.rgba);
}

// Blending onto a transparent background's straight colour: over nothing (alpha 0) the overlay's
// own colour at its coverage; over a partly covered pixel the colours weighted by their shares
// (Porter-Duff over); over an opaque pixel the plain blend, as before.
TEST(OverlayCanvas, BlendsOverStraightAlphaAsPorterDuffOver) {
  Frame image(3, 1);
  const uint8_t pixels[12] = {0, 0, 0, 0, 200, 40, 10, 128, 200, 40, 10, 255};
  std::copy(pixels, pixels + 12, image.rgba.begin());
  const Rgb8 blue{20, 60, 250};
  for (int x = 0; x < 3; ++x) blend_pixel(&image, x, 0, blue, 100);
  EXPECT_EQ(image.rgba[0], 20);  // over nothing: the overlay's colour, exactly
  EXPECT_EQ(image.rgba[1], 60);
  EXPECT_EQ(image.rgba[2], 250);
  EXPECT_EQ(image.rgba[3], 100);
  const double a = 100.0 / 255.0, u = 128.0 / 255.0, out = a + u * (1.0 - a);
  for (int c = 0; c < 3; ++c) {
    const double expected = (blue[size_t(c)] * a + pixels[4 + c] * u * (1.0 - a)) / out;
    EXPECT_NEAR(image.rgba[4 + size_t(c)], expected, 0.5) << c;
    EXPECT_EQ(image.rgba[8 + size_t(c)], (blue[size_t(c)] * 100 + pixels[8 + c] * 155 + 127) / 255)
        << c;
  }
  EXPECT_EQ(image.rgba[7], uint8_t(std::lround(255.0 * out)));
  EXPECT_EQ(image.rgba[11], 255);
}

// Lines whose ends project billions of pixels away (an edge of a box far larger than the view,
// clipped at the near plane): the column range was converted to int unclamped (undefined; on
// x86 a loop from INT_MIN over 2^31 columns). A line through the image darkens its own rows
// only; lines wholly beyond one side draw nothing.
TEST(OverlayCanvas, LinesFromFarBeyondTheImageDrawOnlyWhatCrossesIt) {
  const Rgb8 black{0, 0, 0};
  Frame far = white_frame(40, 30);
  draw_line(&far, {-1e15, 10.5, 0.0}, {1e15, 10.5, 0.0}, 1.0, black, false);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) {
      if (y == 10) EXPECT_LT(pixel(far, x, y)[0], 128) << x;
      if (y < 9 || y > 11) EXPECT_EQ(pixel(far, x, y)[0], 255) << x << ", " << y;
    }
  Frame beyond = white_frame(40, 30);
  draw_line(&beyond, {3e12, 10.5, 0.0}, {5e12, 12.5, 0.0}, 1.0, black, false);
  draw_line(&beyond, {-5e12, -3e12, 0.0}, {-3e12, -1e12, 0.0}, 1.0, black, false);
  draw_line(&beyond, {20.0, 1e15, 0.0}, {21.0, 3e15, 0.0}, 1.0, black, false);
  EXPECT_EQ(beyond.rgba, white_frame(40, 30).rgba);
}

// Corners: a label at top_right lies in the image's right part, inside the margin.
TEST(Overlays, CornerLabelsStayInsideTheMarginAndStack) {
  REQUIRE_TEXT();
  OverlaySettings settings;
  LabelConfig label;
  label.text = "Lantern";
  label.position.corner = OverlayCorner::kTopRight;
  label.color = {1, 0, 0};
  settings.labels = {label, label};
  std::unique_ptr<OverlayPainter> painter;
  ASSERT_OK(OverlayPainter::open(settings, &painter));
  Frame image = white_frame(300, 200);
  painter->draw(settings, OverlayFrame(), &image);
  const int margin = OverlayLayout(300, 200).margin();
  const TextMask mask = font->render("Lantern", label.size);
  int min_x = 300, max_x = -1, min_y = 200, max_y = -1;
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 300; ++x)
      if (pixel(image, x, y)[1] != 255) {
        min_x = std::min(min_x, x), max_x = std::max(max_x, x);
        min_y = std::min(min_y, y), max_y = std::max(max_y, y);
        EXPECT_EQ(pixel(image, x, y)[0], 255);  // red text: the red channel stays full
      }
  EXPECT_GE(min_x, 300 - margin - mask.width);
  EXPECT_LT(max_x, 300 - margin);
  EXPECT_GE(min_y, margin);
  // Two labels stacked: the second starts below the first's rectangle.
  EXPECT_GE(max_y, margin + mask.height);
  EXPECT_LT(max_y, margin + 2 * mask.height + margin);
}

TEST(Legend, NiceTicksAreRoundValuesInsideTheRange) {
  EXPECT_EQ(nice_ticks(0, 10, 5), (std::vector<double>{2, 4, 6, 8}));
  EXPECT_EQ(nice_ticks(-1, 1, 4), (std::vector<double>{-0.5, 0, 0.5}));
  EXPECT_EQ(nice_ticks(0.013, 0.087, 6), (std::vector<double>{0.02, 0.04, 0.06, 0.08}));
  EXPECT_TRUE(nice_ticks(1, 1, 5).empty());
  EXPECT_TRUE(nice_ticks(0, std::nan(""), 5).empty());
  // Ranges a few ulps wide (an almost constant field's automatic range): lo / step is beyond
  // 2^53, where stepping the multiple by one no longer moves it; this never returned.
  for (const auto &[lo, hi] :
       {std::pair{1.0, std::nextafter(1.0, 2.0)}, std::pair{-3.5400000000000005, -3.54},
        std::pair{1.0, 1.0000000000000004}}) {
    const std::vector<double> ticks = nice_ticks(lo, hi, 5);
    EXPECT_LE(ticks.size(), 3u) << lo << " .. " << hi;
    for (const double t : ticks) EXPECT_TRUE(t > lo && t < hi) << t;
  }
  EXPECT_EQ(tick_text(0.04, 0.02), "0.04");
  EXPECT_EQ(tick_text(2000, 500), "2000");
  EXPECT_EQ(tick_text(3e-7, 1e-7), "3e-07");
}

// The colour bar is the scene's colormap table: its top row is the map's high end and its
// bottom row the low end (reversed maps swapped), and it has ticks and labels beside it.
TEST(Legend, BarEndsAreTheColormapEnds) {
  REQUIRE_TEXT();
  for (const bool reverse : {false, true}) {
    for (const std::string name : {"viridis", "coolwarm", "turbo"}) {
      LegendConfig legend;
      legend.enabled = true;
      legend.position.at = std::array<int, 2>{10, 10};
      legend.length = 150;
      legend.width = 16;
      LegendColors colors;
      colors.by = ColorBy::kScalar;
      colors.colormap = name;
      colors.reverse = reverse;
      colors.range = std::array<double, 2>{-2.5, 7.5};
      colors.scalar_name = "c_ke";
      Frame image = white_frame(200, 220);
      OverlayLayout layout(200, 220);
      const LegendBar bar = draw_legend(legend, colors, *font, layout, &image);
      ASSERT_EQ(bar.length, 150);
      const Colormap map = Colormap::choose(name, {}, reverse);  // table() refers into it
      const Colormap::Table &table = map.table();
      for (int x = bar.x; x < bar.x + bar.width; ++x) {
        const auto top = pixel(image, x, bar.y), bottom = pixel(image, x, bar.y + 149);
        EXPECT_EQ((Rgb8{top[0], top[1], top[2]}), table[255]) << name << " x " << x;
        EXPECT_EQ((Rgb8{bottom[0], bottom[1], bottom[2]}), table[0]) << name << " x " << x;
      }
      // The title above the bar and the tick labels to its right are drawn (dark pixels).
      int title = 0, labels = 0;
      for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
          const bool dark = pixel(image, x, y)[0] < 100 && pixel(image, x, y)[2] < 100;
          if (dark && y < bar.y - 3) ++title;
          if (dark && x > bar.x + bar.width + 4) ++labels;
        }
      EXPECT_GT(title, 20) << name;
      EXPECT_GT(labels, 100) << name;
    }
  }
}

TEST(Legend, TypeKeySwatchesAreThePaletteColours) {
  REQUIRE_TEXT();
  LegendConfig legend;
  legend.enabled = true;
  legend.position.at = std::array<int, 2>{5, 5};
  legend.width = 14;
  legend.type_names = {"Ni", "flyer", "void"};
  LegendColors colors;
  colors.by = ColorBy::kType;
  Frame image = white_frame(160, 120);
  OverlayLayout layout(160, 120);
  draw_legend(legend, colors, *font, layout, &image);
  const TypePalette palette({});
  // Each swatch's centre, rows spaced by the name's height and the gap.
  int found = 0;
  for (int type = 0; type < 3; ++type) {
    const Rgb8 want = palette.at(type);
    for (int y = 5; y < 120; ++y) {
      const auto p = pixel(image, 5 + 1 + 7, y);
      if (Rgb8{p[0], p[1], p[2]} == want) {
        ++found;
        break;
      }
    }
  }
  EXPECT_EQ(found, 3);
}

// Orthographic, looking down -z from (0, 0, 50) at the origin, near 10, far 90; the unit box
// [-4, 4]^3 fills 80 of the 100 pixels (half-height 5 at zoom 1: the camera's fit of [-5, 5]).
Camera box_camera(int size) {
  return orthographic_down_z(5.0, 0.0, size, size);
}

TEST(BoxOverlay, EdgesFallOnTheProjectedCornersAndHideBehindNearerDepth) {
  const int size = 100;
  const Camera camera = box_camera(size);
  BoxCorners box{{-4, -3, -4}, {4, 3, 4}};
  BoxOverlayConfig config;
  config.enabled = true;
  config.width = 2;
  Frame image = white_frame(size, size);
  draw_box(config, box, camera, &image);
  // The edge from (-4, -3, 4) to (4, -3, 4): analytic pixels, projected independently.
  LinePoint a, b;
  ASSERT_TRUE(project_point(camera, size, size, {-4, -3, 4}, &a));
  ASSERT_TRUE(project_point(camera, size, size, {4, -3, 4}, &b));
  EXPECT_NEAR(a.y, b.y, 1e-9);
  // Orthographic: pixel = (x * P00 / 2 + 1/2) * width, row = (1/2 - y * P11 / 2) * height.
  EXPECT_NEAR(a.x, (-4 * camera.projection[0][0] * 0.5 + 0.5) * size, 1e-9);
  EXPECT_NEAR(b.x, (4 * camera.projection[0][0] * 0.5 + 0.5) * size, 1e-9);
  EXPECT_NEAR(a.y, (0.5 + 3 * camera.projection[1][1] * 0.5) * size, 1e-9);
  EXPECT_GT(b.x - a.x, 40);
  for (int k = 1; k < 10; ++k) {
    const double x = a.x + (b.x - a.x) * k / 10.0, y = a.y;
    EXPECT_LT(pixel(image, int(x), int(y))[0], 64) << "edge pixel " << x << ", " << y;
  }
  // The box's inside and the outside stay white (away from the edges).
  EXPECT_EQ(pixel(image, size / 2, size / 2)[0], 255);
  EXPECT_EQ(pixel(image, 2, 2)[0], 255);
  // A sphere in front of the edge's middle (nearer depth than the edge's there) hides it; the
  // same depth behind the edge does not.
  const int mx = int((a.x + b.x) / 2), my = int(a.y);
  for (const bool in_front : {true, false}) {
    Frame scene = white_frame(size, size);
    for (int y = my - 6; y <= my + 6; ++y)
      for (int x = mx - 6; x <= mx + 6; ++x)
        scene.depth[scene.index(x, y)] = float(in_front ? a.depth - 0.05 : a.depth + 0.05);
    draw_box(config, box, camera, &scene);
    EXPECT_EQ(pixel(scene, mx, my)[0], in_front ? 255 : pixel(image, mx, my)[0]);
    EXPECT_LT(pixel(scene, mx - 10, my)[0], 64);  // beside the sphere the edge shows
  }
}

// A triclinic box: its edges run between the corners low + i a + j b + k c (a = (8, 0, 0),
// b = (2, 6, 0), c = (1, -1, 8) from (-4, -3, -4)), seen from above: the top face is a
// parallelogram sheared by xy and moved by (xz, yz); the axis-aligned box's top-right corner
// stays white.
TEST(BoxOverlay, TriclinicEdgesJoinTheTiltedCorners) {
  const int size = 100;
  const Camera camera = box_camera(size);
  BoxCorners box{{-4, -3, -4}, {4, 3, 4}, {2, 1, -1}};  // xy, xz, yz
  BoxOverlayConfig config;
  config.enabled = true;
  config.width = 2;
  Frame image = white_frame(size, size);
  draw_box(config, box, camera, &image);
  // The top face's edge along b from the corner low + c to low + b + c: (-3, -4) to (-1, 2).
  LinePoint p, q;
  ASSERT_TRUE(project_point(camera, size, size, {-3, -4, 4}, &p));
  ASSERT_TRUE(project_point(camera, size, size, {-1, 2, 4}, &q));
  for (int k = 1; k < 10; ++k) {
    const double x = p.x + (q.x - p.x) * k / 10.0, y = p.y + (q.y - p.y) * k / 10.0;
    EXPECT_LT(pixel(image, int(x), int(y))[0], 64) << "edge pixel " << x << ", " << y;
  }
  // The axis-aligned box's edge x = -4 at y = 0 is inside the sheared faces: no line there.
  LinePoint inside;
  ASSERT_TRUE(project_point(camera, size, size, {-4, 0, 4}, &inside));
  EXPECT_EQ(pixel(image, int(inside.x), int(inside.y))[0], 255);
  // Zero tilt draws the axis-aligned box's bytes.
  Frame plain = white_frame(size, size), zero = white_frame(size, size);
  draw_box(config, BoxCorners{{-4, -3, -4}, {4, 3, 4}}, camera, &plain);
  draw_box(config, BoxCorners{{-4, -3, -4}, {4, 3, 4}, {0, 0, 0}}, camera, &zero);
  ASSERT_EQ(plain.rgba.size(), zero.rgba.size());
  EXPECT_EQ(std::memcmp(plain.rgba.data(), zero.rgba.data(), plain.rgba.size()), 0);
}

}  // namespace
}  // namespace lantern::testing
