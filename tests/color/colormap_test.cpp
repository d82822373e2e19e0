// Colormaps: the tables are their published definitions (spot entries computed by hand from the
// sources' numbers), the four maps Lantern had before keep their bytes, reverse and custom maps,
// and colormap files.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/color/colormap.h"
#include "core/color/colormap_file.h"

namespace lantern {
namespace {

uint64_t fnv1a(const Colormap::Table &table) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (const Rgb8 &c : table)
    for (const uint8_t byte : c) h = (h ^ byte) * 0x100000001b3ull;
  return h;
}

Rgb8 entry(const std::string &name, size_t i) {
  return Colormap::named(name)->table()[i];
}

// The tables of viridis, plasma, coolwarm and grayscale as Lantern shipped them before the
// tables were computed from colormap_data.h: images colored by them must not change.
TEST(Colormap, TheEarlierMapsKeepTheirBytes) {
  EXPECT_EQ(fnv1a(Colormap::named("viridis")->table()), 0x1b8e5490518c939bull);
  EXPECT_EQ(fnv1a(Colormap::named("plasma")->table()), 0xb80f5cf20e4372dcull);
  EXPECT_EQ(fnv1a(Colormap::named("coolwarm")->table()), 0x01f4363b8d8cbdc5ull);
  EXPECT_EQ(fnv1a(Colormap::named("grayscale")->table()), 0x3ac8574c48f9b025ull);
}

// round(v * 255) of the published values, worked out by hand.
TEST(Colormap, NewMapsMatchTheirPublishedEnds) {
  EXPECT_EQ(entry("inferno", 0), (Rgb8{0, 0, 4}));          // 0.001462, 0.000466, 0.013866
  EXPECT_EQ(entry("inferno", 255), (Rgb8{252, 255, 164}));  // 0.988362, 0.998364, 0.644924
  EXPECT_EQ(entry("magma", 255), (Rgb8{252, 253, 191}));    // 0.987053, 0.991438, 0.749504
  EXPECT_EQ(entry("cividis", 0), (Rgb8{0, 34, 78}));        // 0.000000, 0.135112, 0.304751
  EXPECT_EQ(entry("cividis", 255), (Rgb8{254, 232, 56}));   // 0.995737, 0.909344, 0.217772
  EXPECT_EQ(entry("turbo", 0), (Rgb8{48, 18, 59}));         // 0.18995, 0.07176, 0.23217
  EXPECT_EQ(entry("turbo", 255), (Rgb8{122, 4, 3}));        // 0.47960, 0.01583, 0.01055
  EXPECT_EQ(entry("RdBu", 0), (Rgb8{103, 0, 31}));          // ColorBrewer #67001f
  EXPECT_EQ(entry("RdBu", 255), (Rgb8{5, 48, 97}));         // ColorBrewer #053061
  EXPECT_EQ(entry("seismic", 255), (Rgb8{128, 0, 0}));      // (0.5, 0, 0)
  // The diverging maps are near white in the middle.
  for (const char *name : {"RdBu", "seismic", "coolwarm"})
    for (const size_t i : {127u, 128u})
      for (const uint8_t c : entry(name, i)) EXPECT_GE(c, 200) << name << "[" << i << "]";
  EXPECT_EQ(Colormap::names().size(), 10u);
  EXPECT_FALSE(Colormap::named("jet"));
}

TEST(Colormap, ReverseRunsTheMapBackwards) {
  const Colormap map = *Colormap::named("turbo"), back = map.reversed();
  for (size_t i = 0; i < 256; ++i) EXPECT_EQ(back.table()[i], map.table()[255 - i]);
  EXPECT_EQ(back.at(0.0, 0.0, 1.0), map.at(1.0, 0.0, 1.0));
  EXPECT_EQ(Colormap::choose("turbo", {}, true).table(), back.table());
}

TEST(Colormap, RangesWiderThanTheLargestDoubleStillSpreadTheValues) {
  // A scalar field with "missing value" sentinels at +-1e308: hi - lo overflows. The top value
  // was inf / inf = NaN, converted to a table index (a crash), and every other value 0 (the
  // low end).
  const Colormap map = *Colormap::named("viridis");
  const double lo = -1e308, hi = 1e308;
  EXPECT_EQ(map.at(hi, lo, hi), map.table()[255]);
  EXPECT_EQ(map.at(lo, lo, hi), map.table()[0]);
  EXPECT_EQ(map.at(0.0, lo, hi), map.table()[128]);
  EXPECT_EQ(map.at(0.5e308, lo, hi), map.table()[191]);  // 0.75 x 255 + 0.5 = 191.75
  EXPECT_EQ(map.at(std::numeric_limits<double>::infinity(), lo, hi), map.table()[255]);
  EXPECT_EQ(Colormap::range_fraction(0.25, 0.0, 1.0), 0.25);  // the plain quotient otherwise
}

TEST(Colormap, CustomPointsAreEvenlySpacedAndLinear) {
  // Black to white in two points is the grayscale ramp exactly.
  EXPECT_EQ(Colormap::from_colors({{0, 0, 0}, {1, 1, 1}}).table(),
            Colormap::named("grayscale")->table());
  // Three points: red, green, blue at 0, 0.5, 1.
  const Colormap rgb = Colormap::from_colors({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  EXPECT_EQ(rgb.table()[0], (Rgb8{255, 0, 0}));
  EXPECT_EQ(rgb.table()[255], (Rgb8{0, 0, 255}));
  // 0.25 is entry 64: 128/255 of the way to green, so red 255 - 128 = 127 and green 128.
  EXPECT_EQ(rgb.at(0.25, 0.0, 1.0), (Rgb8{127, 128, 0}));
  // 256 points are the table itself; a custom list wins over the name.
  std::vector<std::array<double, 3>> ramp;
  for (int i = 0; i < 256; ++i) ramp.push_back({i / 255.0, 0.0, 1.0 - i / 255.0});
  const Colormap listed = Colormap::choose("viridis", ramp, false);
  for (int i = 0; i < 256; ++i)
    EXPECT_EQ(listed.table()[size_t(i)], (Rgb8{uint8_t(i), 0, uint8_t(255 - i)}));
}

TEST(ColormapFile, ReadsUnitAndByteValuedRows) {
  std::vector<std::array<double, 3>> colors;
  ASSERT_TRUE(
      parse_colormap_text("# a map\n0 0 0\n\n0.5, 0.25, 1  # mid\n1\t1\t1\n", "f", &colors).ok());
  ASSERT_EQ(colors.size(), 3u);
  EXPECT_EQ(colors[1], (std::array<double, 3>{0.5, 0.25, 1.0}));
  ASSERT_TRUE(parse_colormap_text("0,0,0\n255,128,0\n", "f", &colors).ok());
  EXPECT_EQ(colors[1], (std::array<double, 3>{1.0, 128 / 255.0, 0.0}));
}

TEST(ColormapFile, BadFilesNameTheFileLineAndProblem) {
  std::vector<std::array<double, 3>> colors;
  const auto error = [&](const std::string &text) {
    const Status s = parse_colormap_text(text, "map.txt", &colors);
    EXPECT_EQ(s.code, StatusCode::kConfig);
    return s.message;
  };
  EXPECT_NE(error("0 0 0\n1 1\n").find("map.txt' line 2: expected 3 numbers"), std::string::npos);
  EXPECT_NE(error("0 0 0\n1 x 1\n").find("line 2: 'x' is not a finite number"), std::string::npos);
  EXPECT_NE(error("0 0 -1\n1 1 1\n").find("line 1: a colour component is negative"),
            std::string::npos);
  EXPECT_NE(error("0 0 300\n1 1 1\n").find("exceeds 255"), std::string::npos);
  EXPECT_NE(error("# only\n0 0 0\n").find("needs at least 2 colours, has 1"), std::string::npos);
  EXPECT_NE(error("0 0 nan\n1 1 1\n").find("not a finite number"), std::string::npos);
  const Status missing = read_colormap_file("/nonexistent/map.txt", &colors);
  EXPECT_EQ(missing.code, StatusCode::kConfig);
  EXPECT_NE(missing.message.find("cannot read colormap file '/nonexistent/map.txt'"),
            std::string::npos)
      << missing.message;
  // Not a regular file: a FIFO nobody writes to blocked the read for ever; /dev/zero never ended.
  const std::string fifo = ::testing::TempDir() + "lantern_colormap_fifo";
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string &path : {fifo, std::string("/dev/zero")}) {
    const Status s = read_colormap_file(path, &colors);
    EXPECT_EQ(s.code, StatusCode::kConfig) << path;
    EXPECT_NE(s.message.find("not a regular file (a colormap is a text file of colours)"),
              std::string::npos)
        << s.message;
  }
  ::unlink(fifo.c_str());
}

TEST(TypePalette, EveryTypeWrapsModuloThePaletteSize) {
  // Types within the palette take a shortcut; every type, negative and past the end included,
  // must still get palette[type mod size].
  const std::vector<std::array<double, 3>> three = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const TypePalette custom(three), builtin({});
  const TypePalette *palettes[] = {&custom, &builtin};
  for (const TypePalette *p : palettes) {
    int64_t n = 1;
    while (n < 64 && !(p->at(n) == p->at(0))) ++n;  // the palette's size: the first repeat
    ASSERT_LT(n, 64);
    for (int64_t t = -3 * n - 1; t <= 3 * n + 1; ++t)
      EXPECT_EQ(p->at(t), p->at(((t % n) + n) % n)) << "type " << t;
    EXPECT_EQ(p->at(INT64_MIN), p->at(((INT64_MIN % n) + n) % n));
    EXPECT_EQ(p->at(INT64_MAX), p->at(INT64_MAX % n));
  }
  EXPECT_EQ(custom.at(4), (Rgb8{0, 255, 0}));
  EXPECT_EQ(custom.at(-1), (Rgb8{0, 0, 255}));
}

}  // namespace
}  // namespace lantern
