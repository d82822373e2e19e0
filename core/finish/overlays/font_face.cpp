// FontFace through FreeType (glyphs) and fontconfig (finding the font).
#include "core/finish/overlays/font_face.h"

#include <fontconfig/fontconfig.h>
#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <utility>

namespace lantern {
namespace {

// One glyph at one size, as FreeType rendered it (8-bit antialiased coverage).
struct Glyph {
  unsigned index = 0;     // the font's glyph index (for kerning)
  int left = 0, top = 0;  // bitmap's offset from the pen: right, and up from the baseline
  int width = 0, rows = 0;
  int advance = 0;  // pixels (hinted advances are whole pixels)
  std::vector<uint8_t> coverage;
};

// The next code point of `s` from *i (U+FFFD for a malformed sequence).
char32_t next_code_point(const std::string &s, size_t *i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char b = byte(*i);
  int extra = b < 0x80 ? 0 : (b >> 5) == 6 ? 1 : (b >> 4) == 14 ? 2 : (b >> 3) == 30 ? 3 : -1;
  if (extra < 0 || *i + extra >= s.size() + (extra == 0 ? 1 : 0)) {
    ++*i;
    return 0xFFFD;
  }
  char32_t c = extra == 0 ? b : (b & (0x3F >> extra));
  for (int k = 1; k <= extra; ++k) {
    if ((byte(*i + k) & 0xC0) != 0x80) {
      ++*i;
      return 0xFFFD;
    }
    c = (c << 6) | (byte(*i + k) & 0x3F);
  }
  *i += extra + 1;
  return c;
}

std::string fc_string(FcPattern *pattern, const char *object) {
  FcChar8 *value = nullptr;
  if (FcPatternGetString(pattern, object, 0, &value) != FcResultMatch || value == nullptr)
    return "";
  return reinterpret_cast<const char *>(value);
}

// Case-insensitive comparison of family names (fontconfig's own matching ignores case).
bool same_family(const std::string &a, const std::string &b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

// The file of fontconfig's best match for `family`, if its family is `family` (fontconfig
// always offers something; a substitute is not the font that was asked for).
Status match_family(const std::string &family, std::string *file) {
  const Status missing{StatusCode::kConfig,
                       "font: fontconfig has no font of family '" + family +
                           "' (install fonts-dejavu-core for the default DejaVu Sans, or give "
                           "font: PATH to a .ttf/.otf file)"};
  std::unique_ptr<FcConfig, void (*)(FcConfig *)> config(FcInitLoadConfigAndFonts(),
                                                         FcConfigDestroy);
  if (!config) return missing;
  std::unique_ptr<FcPattern, void (*)(FcPattern *)> pattern(
      FcNameParse(reinterpret_cast<const FcChar8 *>(family.c_str())), FcPatternDestroy);
  if (!pattern) return missing;
  FcConfigSubstitute(config.get(), pattern.get(), FcMatchPattern);
  FcDefaultSubstitute(pattern.get());
  FcResult result = FcResultNoMatch;
  std::unique_ptr<FcPattern, void (*)(FcPattern *)> match(
      FcFontMatch(config.get(), pattern.get(), &result), FcPatternDestroy);
  if (!match || result != FcResultMatch) return missing;
  const std::string found = fc_string(match.get(), FC_FAMILY);
  *file = fc_string(match.get(), FC_FILE);
  if (file->empty() || !same_family(found, family))
    return {StatusCode::kConfig,
            missing.message + (found.empty() ? std::string() : "; it offered '" + found + "'")};
  return {};
}

}  // namespace

struct FontFace::Impl {
  FT_Library library = nullptr;
  FT_Face face = nullptr;
  int size = 0;  // the pixel size set on the face
  std::map<std::pair<char32_t, int>, Glyph> glyphs;

  ~Impl() {
    if (face != nullptr) FT_Done_Face(face);
    if (library != nullptr) FT_Done_FreeType(library);
  }

  void set_size(int pixel_size) {
    if (size == pixel_size) return;
    FT_Set_Pixel_Sizes(face, 0, FT_UInt(pixel_size));
    size = pixel_size;
  }

  const Glyph &glyph(char32_t c, int pixel_size) {
    auto found = glyphs.find({c, pixel_size});
    if (found != glyphs.end()) return found->second;
    set_size(pixel_size);
    Glyph g;
    g.index = FT_Get_Char_Index(face, FT_ULong(c));
    if (FT_Load_Glyph(face, g.index, FT_LOAD_RENDER) == 0) {
      const FT_GlyphSlot slot = face->glyph;
      const FT_Bitmap &bitmap = slot->bitmap;
      g.left = slot->bitmap_left;
      g.top = slot->bitmap_top;
      g.advance = int((slot->advance.x + 32) >> 6);
      if (bitmap.pixel_mode == FT_PIXEL_MODE_GRAY && bitmap.buffer != nullptr) {
        g.width = int(bitmap.width);
        g.rows = int(bitmap.rows);
        g.coverage.resize(size_t(g.width) * size_t(g.rows));
        for (int y = 0; y < g.rows; ++y)
          std::copy_n(bitmap.buffer + y * bitmap.pitch, g.width, g.coverage.begin() + y * g.width);
      }
    }
    return glyphs.emplace(std::make_pair(c, pixel_size), std::move(g)).first->second;
  }

  int kerning(unsigned left, unsigned right) const {
    if (left == 0 || !FT_HAS_KERNING(face)) return 0;
    FT_Vector delta{0, 0};
    if (FT_Get_Kerning(face, left, right, FT_KERNING_DEFAULT, &delta) != 0) return 0;
    return int((delta.x + 32) >> 6);
  }
};

bool text_available() {
  return true;
}

Status find_font_file(const std::string &font, std::string *file) {
  if (font.find('/') == std::string::npos)
    return match_family(font.empty() ? kDefaultFontFamily : font, file);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(font, ec))
    return {StatusCode::kConfig, "font: '" + font + "' is not a font file (no such file)"};
  *file = font;
  return {};
}

FontFace::FontFace(std::unique_ptr<Impl> impl, std::string file)
    : impl_(std::move(impl)), file_(std::move(file)) {}
FontFace::~FontFace() = default;

Status FontFace::open(const std::string &file, std::unique_ptr<FontFace> *out) {
  auto impl = std::make_unique<Impl>();
  if (FT_Init_FreeType(&impl->library) != 0)
    return {StatusCode::kConfig, "font: FreeType could not start"};
  if (FT_New_Face(impl->library, file.c_str(), 0, &impl->face) != 0)
    return {StatusCode::kConfig, "font: FreeType cannot read '" + file + "' as a font"};
  if (!FT_IS_SCALABLE(impl->face))
    return {StatusCode::kConfig, "font: '" + file + "' is a bitmap font; give a scalable one"};
  out->reset(new FontFace(std::move(impl), file));
  return {};
}

int FontFace::measure(const std::string &utf8, int pixel_size) {
  int pen = 0, right = 0;
  unsigned previous = 0;
  for (size_t i = 0; i < utf8.size();) {
    const Glyph &g = impl_->glyph(next_code_point(utf8, &i), pixel_size);
    pen += impl_->kerning(previous, g.index);
    right = std::max({right, pen + g.left + g.width, pen + g.advance});
    pen += g.advance;
    previous = g.index;
  }
  return right;
}

TextMask FontFace::render(const std::string &utf8, int pixel_size) {
  impl_->set_size(pixel_size);
  const FT_Size_Metrics &metrics = impl_->face->size->metrics;
  int ascent = int((metrics.ascender + 63) >> 6), descent = int((-metrics.descender + 63) >> 6);
  // Pen positions first (glyphs may reach above the ascender, e.g. accents).
  struct Placed {
    const Glyph *glyph;
    int x;
  };
  std::vector<Placed> placed;
  int pen = 0, right = 0;
  unsigned previous = 0;
  for (size_t i = 0; i < utf8.size();) {
    const Glyph &g = impl_->glyph(next_code_point(utf8, &i), pixel_size);
    pen += impl_->kerning(previous, g.index);
    placed.push_back({&g, pen});
    right = std::max({right, pen + g.left + g.width, pen + g.advance});
    ascent = std::max(ascent, g.top);
    descent = std::max(descent, g.rows - g.top);
    pen += g.advance;
    previous = g.index;
  }
  TextMask mask;
  mask.width = right;
  mask.height = ascent + descent;
  mask.baseline = ascent;
  mask.coverage.assign(size_t(mask.width) * size_t(mask.height), 0);
  for (const Placed &p : placed) {
    const Glyph &g = *p.glyph;
    for (int y = 0; y < g.rows; ++y) {
      const int row = ascent - g.top + y;
      for (int x = 0; x < g.width; ++x) {
        const int column = p.x + g.left + x;
        if (row < 0 || row >= mask.height || column < 0 || column >= mask.width) continue;
        uint8_t &c = mask.coverage[size_t(row) * mask.width + column];
        c = std::max(c, g.coverage[size_t(y) * g.width + x]);
      }
    }
  }
  return mask;
}

}  // namespace lantern
