// `background: transparent` through the C API: alpha 0 where nothing is drawn, 255 where a sphere
// is, partial coverage on super-sampled silhouettes; the transparent image composited over a
// colour B gives the opaque image rendered on B (both renderers); PNG (straight alpha) and EXR
// (premultiplied) composite to the same pixels; the depth cue fades towards alpha 0; text over
// nothing keeps its colour with antialiased alpha; density images; formats without alpha refused
// at lantern_open.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tests/api/api_fixture.h"
#include "tests/support/image_file.h"

namespace lantern::testing {
namespace {

constexpr double kBackground[3] = {0.1, 0.2, 0.3};
const char *const kBackgroundYaml = "[0.1, 0.2, 0.3]";

double srgb_decode(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}
double srgb_encode(double v) {
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}
// The byte Lantern clears an opaque background to (core/color/colormap.h's to_rgb8).
double background_byte(int c) {
  return std::lround(kBackground[c] * 255.0);
}

// OpenImageIO premultiplies a PNG while reading it, on the sRGB-encoded values, which is not
// what compositing in linear light needs: the tests read the bytes as stored (straight alpha).
ImagePixels read_stored(const std::string &path) {
  return read_image(path, true);
}

class TransparentBackground : public ApiTest {
 protected:
  // One sphere of radius 1 at the origin, seen head-on from 10 units: it covers the middle of a
  // 64 x 64 image, the corners stay empty.
  std::string sphere_scene(const std::string &name, const std::string &background,
                           const std::string &extra = "", const std::string &ext = "png",
                           const std::string &color = "{by: solid, solid: [0.9, 0.5, 0.1]}") const {
    return "scenes:\n  - name: " + name +
           "\n    width: 64\n    height: 64\n    radius: 1.0\n    background: " + background +
           "\n    camera: {position: [0, 0, 10], look_at: [0, 0, 0], up: [0, 1, 0]}\n"
           "    color: " +
           color + "\n    output: {pattern: '" + (dir_ / (name + "_{step:04d}." + ext)).string() +
           "'}\n" + extra;
  }
  std::string file(const std::string &name, const std::string &ext = "png") const {
    return (dir_ / (name + "_0000." + ext)).string();
  }
  void render(const std::string &config, const std::vector<double> &x) {
    ASSERT_EQ(open(config), LANTERN_OK) << message();
    const lantern_particles p = interleaved(x);
    ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
    ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
    lantern_close(ctx_);
    ctx_ = nullptr;
  }
  bool have_gl() {
    const bool ok =
        open(sphere_scene("probe", "[1, 1, 1]", "    renderer: opengl\n")) == LANTERN_OK;
    lantern_close(ctx_);
    ctx_ = nullptr;
    return ok;
  }
  std::vector<const char *> renderers() {
    std::vector<const char *> r = {"cpu"};
    if (have_gl()) r.push_back("opengl");
    return r;
  }
};

const std::vector<double> kOneSphere = {0.0, 0.0, 0.0};

TEST_F(TransparentBackground, EmptyPixelsHaveAlphaZeroSpheresAlphaOneEdgesPartialAlpha) {
  for (const char *renderer : renderers()) {
    for (int samples : {1, 4}) {
      SCOPED_TRACE(std::string(renderer) + ", samples " + std::to_string(samples));
      const std::string name = std::string(renderer) + std::to_string(samples);
      render(sphere_scene(
                 name, "transparent",
                 "    samples: " + std::to_string(samples) + "\n    renderer: " + renderer + "\n"),
             kOneSphere);
      const ImagePixels img = read_stored(file(name));
      ASSERT_EQ(img.error, "");
      ASSERT_EQ(img.channels, 4);  // RGBA
      const auto alpha = [&img](int x, int y) { return img.pixels[(size_t(y) * 64 + x) * 4 + 3]; };
      for (const auto &[x, y] : {std::pair{0, 0}, {63, 0}, {0, 63}, {63, 63}})
        EXPECT_EQ(alpha(x, y), 0) << "corner " << x << ", " << y;
      EXPECT_EQ(alpha(32, 32), 255);
      int partial = 0, covered = 0;
      for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
          partial += alpha(x, y) > 0 && alpha(x, y) < 255;
          covered += alpha(x, y) == 255;
        }
      EXPECT_GT(covered, 100);
      if (samples == 1)
        EXPECT_EQ(partial, 0);  // one sample: a pixel is covered or not
      else
        EXPECT_GT(partial, 20);  // the silhouette's antialiased ring
    }
  }
}

// Straight alpha done right: the transparent image composited over B (in linear light, as the
// down-sampling averages) is the image rendered opaque on B, up to the 8-bit rounding of colour
// and alpha; at one sample exactly.
TEST_F(TransparentBackground, CompositedOverTheBackgroundItIsTheOpaqueImage) {
  for (const char *renderer : renderers()) {
    for (int samples : {1, 4, 16}) {
      SCOPED_TRACE(std::string(renderer) + ", samples " + std::to_string(samples));
      const std::string tag = std::string(renderer) + std::to_string(samples);
      const std::string extra =
          "    samples: " + std::to_string(samples) + "\n    renderer: " + renderer + "\n";
      render(sphere_scene("clear" + tag, "transparent", extra), kOneSphere);
      render(sphere_scene("opaque" + tag, kBackgroundYaml, extra), kOneSphere);
      const FloatImagePixels clear = read_float_image(file("clear" + tag), true);
      const ImagePixels opaque = read_image(file("opaque" + tag));
      ASSERT_EQ(clear.error, "");
      ASSERT_EQ(opaque.error, "");
      ASSERT_EQ(clear.channels, 4);
      ASSERT_EQ(opaque.channels, 3);  // every pixel opaque: RGB
      double worst = 0;
      for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
          const float *p = clear.at(x, y);
          for (int c = 0; c < 3; ++c) {
            const double linear =
                srgb_decode(p[c]) * p[3] + srgb_decode(background_byte(c) / 255.0) * (1.0 - p[3]);
            const double composited = 255.0 * srgb_encode(linear);
            worst = std::max(
                worst, std::abs(composited - double(opaque.pixels[(size_t(y) * 64 + x) * 3 + c])));
          }
        }
      EXPECT_LE(worst, samples == 1 ? 1e-3 : 1.0) << "levels of 255";
      std::printf("%s, samples %d: composited over B vs opaque on B, worst %.3f levels\n", renderer,
                  samples, worst);
    }
  }
}

// Both renderers give the same transparent image up to the rounding they already differ by.
TEST_F(TransparentBackground, CpuRasterAndOpenGlAgreeOnAlpha) {
  if (!have_gl()) GTEST_SKIP() << "no OpenGL in this build or machine";
  for (const char *renderer : {"cpu", "opengl"})
    render(sphere_scene(renderer, "transparent",
                        "    samples: 4\n    renderer: " + std::string(renderer) + "\n"),
           kOneSphere);
  const ImagePixels cpu = read_stored(file("cpu")), gl = read_stored(file("opengl"));
  ASSERT_EQ(cpu.error, "");
  ASSERT_EQ(gl.error, "");
  ASSERT_EQ(cpu.pixels.size(), gl.pixels.size());
  int worst_alpha = 0, differing = 0;
  for (size_t i = 3; i < cpu.pixels.size(); i += 4) {
    const int d = std::abs(int(cpu.pixels[i]) - int(gl.pixels[i]));
    worst_alpha = std::max(worst_alpha, d);
    differing += d != 0;
  }
  // A silhouette sample within float rounding of its centre may flip: one sample of four.
  EXPECT_LE(worst_alpha, 64);
  EXPECT_LE(differing, 8);
  std::printf("samples 4, cpu raster vs opengl: alpha differs in %d pixels, by at most %d\n",
              differing, worst_alpha);
}

// PNG stores straight alpha, EXR premultiplied linear colour: over any background both files
// give the same pixel.
TEST_F(TransparentBackground, PngAndExrCompositeToTheSamePixels) {
  const std::string extra = "    samples: 16\n    renderer: cpu\n";
  render(sphere_scene("png", "transparent", extra, "png"), kOneSphere);
  render(sphere_scene("exr", "transparent", extra, "exr"), kOneSphere);
  const FloatImagePixels png = read_float_image(file("png", "png"), true);
  const FloatImagePixels exr = read_float_image(file("exr", "exr"));
  ASSERT_EQ(png.error, "");
  ASSERT_EQ(exr.error, "");
  ASSERT_EQ(png.channels, 4);
  ASSERT_GE(exr.channels, 4);
  ASSERT_EQ(exr.alpha_channel, 3);
  EXPECT_EQ(exr.names[3], "A");
  int partial = 0;
  double worst = 0;
  for (const double under : {0.0, 0.5, 1.0})
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) {
        const float *p = png.at(x, y), *e = exr.at(x, y);
        EXPECT_NEAR(p[3], e[3], 1e-3);
        partial += under == 0.0 && p[3] > 0.0f && p[3] < 1.0f;
        for (int c = 0; c < 3; ++c) {
          const double from_png = srgb_decode(p[c]) * p[3] + under * (1.0 - p[3]);
          const double from_exr = e[c] + under * (1.0 - e[3]);
          worst = std::max(worst, std::abs(from_png - from_exr));
        }
      }
  EXPECT_GT(partial, 20);
  EXPECT_LT(worst, 2e-3);  // half floats: 11 significant bits
  std::printf("PNG vs EXR composited over 0, 0.5, 1: worst %.2e (linear)\n", worst);
}

// depth_cue without a colour fades towards alpha 0: the near sphere (view depths 8..10, before the
// fade starts at 10.5) stays opaque, the far one (12..14, fading to 16) is partly transparent, and
// both keep the colour they have without the cue.
TEST_F(TransparentBackground, DepthCueFadesAlphaAndKeepsColour) {
  const std::vector<double> two = {-1.2, 0.0, 1.0, 1.2, 0.0, -3.0};
  const std::string extra = "    renderer: cpu\n";
  render(sphere_scene("plain", "transparent", extra), two);
  render(sphere_scene("cued", "transparent", extra + "    depth_cue: {start: 10.5, end: 16}\n"),
         two);
  const ImagePixels plain = read_stored(file("plain")), cued = read_stored(file("cued"));
  ASSERT_EQ(plain.error, "");
  ASSERT_EQ(cued.error, "");
  ASSERT_EQ(cued.channels, 4);
  int near_pixels = 0, far_pixels = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const size_t i = (size_t(y) * 64 + x) * 4;
      if (plain.pixels[i + 3] == 0) {
        EXPECT_EQ(cued.pixels[i + 3], 0) << x << ", " << y;
        continue;
      }
      if (x < 32) {  // the near sphere, left of the middle
        ++near_pixels;
        EXPECT_EQ(cued.pixels[i + 3], 255) << x << ", " << y;
      } else {
        ++far_pixels;
        EXPECT_GT(cued.pixels[i + 3], 0) << x << ", " << y;
        EXPECT_LT(cued.pixels[i + 3], 220) << x << ", " << y;  // faded by at least 0.27
      }
      for (int c = 0; c < 3; ++c) EXPECT_EQ(cued.pixels[i + c], plain.pixels[i + c]);
    }
  EXPECT_GT(near_pixels, 200);
  EXPECT_GT(far_pixels, 100);
}

#if LANTERN_TEST_TEXT
// A label over nothing: its pixels keep the label's colour exactly, the glyphs' antialiased edges
// carry partial alpha, the rest stays at alpha 0.
TEST_F(TransparentBackground, TextOverNothingKeepsItsColourWithAntialiasedAlpha) {
  const std::vector<double> out_of_view = {100.0, 0.0, 0.0};
  render(sphere_scene("label", "transparent",
                      "    renderer: cpu\n    labels: [{text: 'Lantern 42', size: 14, color: "
                      "[1, 0, 0]}]\n"),
         out_of_view);
  const ImagePixels img = read_stored(file("label"));
  ASSERT_EQ(img.error, "");
  ASSERT_EQ(img.channels, 4);
  int partial = 0, solid = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const uint8_t *p = &img.pixels[(size_t(y) * 64 + x) * 4];
      if (p[3] == 0) continue;
      partial += p[3] < 255;
      solid += p[3] == 255;
      EXPECT_EQ(p[0], 255) << x << ", " << y;
      EXPECT_EQ(p[1], 0) << x << ", " << y;
      EXPECT_EQ(p[2], 0) << x << ", " << y;
    }
  EXPECT_GT(partial, 10);
  EXPECT_GT(solid, 0);
}
#endif

// style: density: where no footprint reached alpha 0, elsewhere the mean colour covering t.
TEST_F(TransparentBackground, DensityImagesLeaveEmptyPixelsTransparent) {
  const std::vector<double> x = {0.0, 0.0, 0.0, 0.6, 0.3, 0.0};  // footprints of radius 1
  render(sphere_scene("density", "transparent", "    style: density\n", "png",
                      "{by: solid, solid: [0.9, 0.5, 0.1]}"),
         x);
  render(sphere_scene("density_type", "transparent", "    style: density\n", "png", "{by: type}"),
         x);
  for (const char *name : {"density", "density_type"}) {
    SCOPED_TRACE(name);
    const ImagePixels img = read_stored(file(name));
    ASSERT_EQ(img.error, "");
    ASSERT_EQ(img.channels, 4);
    EXPECT_EQ(img.pixels[3], 0);
    int seen = 0, partial = 0;
    for (size_t i = 3; i < img.pixels.size(); i += 4) {
      seen += img.pixels[i] > 0;
      partial += img.pixels[i] > 0 && img.pixels[i] < 255;
    }
    EXPECT_GT(seen, 100);
    // One channel: the colormap is the pixel (opaque); by type: the transfer is the alpha.
    if (std::string(name) == "density")
      EXPECT_EQ(partial, 0);
    else
      EXPECT_GT(partial, 100);
  }
}

TEST_F(TransparentBackground, FormatsWithoutAlphaAreConfigErrorsAtOpen) {
  EXPECT_EQ(open(sphere_scene("jpeg", "transparent", "", "jpg")), LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("background"), std::string::npos) << message();
  EXPECT_NE(message().find("JPEG"), std::string::npos) << message();
  EXPECT_EQ(open(sphere_scene("bad", "clear")), LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("'transparent'"), std::string::npos) << message();
#if LANTERN_TEST_MOVIES
  const std::string movie =
      "scenes:\n  - name: m\n    background: transparent\n"
      "    output: {movie: {file: '" +
      (dir_ / "m.mp4").string() + "'}}\n";
  EXPECT_EQ(open(movie), LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("background"), std::string::npos) << message();
  EXPECT_NE(message().find("output.movie"), std::string::npos) << message();
#endif
  // The same scene with a colour, or writing PNG, TIFF or EXR, opens.
  EXPECT_EQ(open(sphere_scene("jpeg", kBackgroundYaml, "", "jpg")), LANTERN_OK) << message();
  for (const char *ext : {"png", "tif", "exr"})
    EXPECT_EQ(open(sphere_scene(ext, "transparent", "", ext)), LANTERN_OK) << message();
}

}  // namespace
}  // namespace lantern::testing
