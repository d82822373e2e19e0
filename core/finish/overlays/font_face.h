// A real font for overlay text: found through fontconfig (DejaVu Sans by default) or given as a
// file, and drawn by FreeType into antialiased 8-bit coverage masks.
//
// Built with FreeType and fontconfig (LANTERN_WITH_TEXT); without them text_available() is false,
// and find and open say that the build lacks text (kConfig). Ownership: a FontFace owns its
// FreeType library and face, and its glyph cache; no global state (fontconfig's configuration is
// built and released per lookup). Thread-safety: one thread at a time per FontFace.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/common/status.h"

namespace lantern {

// The family fontconfig is asked for when the configuration names no font.
inline constexpr const char *kDefaultFontFamily = "DejaVu Sans";

// Whether this build draws text (FreeType and fontconfig were found).
bool text_available();

// The font file for `font`: a path (contains '/'), which must exist; a fontconfig family name;
// or "" for kDefaultFontFamily. kConfig naming what was looked for when there is no such font
// (fontconfig offering another family counts as none), or when the build has no text.
Status find_font_file(const std::string &font, std::string *file);

// A run of text as coverage: width x height bytes, 0 (none) to 255 (full), row 0 at the top.
// `baseline`: the row of the text's baseline; the box spans the font's ascender to descender.
struct TextMask {
  int width = 0, height = 0;
  int baseline = 0;
  std::vector<uint8_t> coverage;
};

class FontFace {
 public:
  // Opens `file` (from find_font_file). kConfig naming the file when FreeType cannot read it.
  static Status open(const std::string &file, std::unique_ptr<FontFace> *out);
  ~FontFace();
  FontFace(const FontFace &) = delete;
  FontFace &operator=(const FontFace &) = delete;

  // `utf8` at `pixel_size` (the font's em in pixels), glyphs hinted and antialiased by FreeType,
  // kerned where the font says. Characters the font lacks draw as its missing-glyph box.
  TextMask render(const std::string &utf8, int pixel_size);
  // The width the text would take, pixels (render's mask width).
  int measure(const std::string &utf8, int pixel_size);
  const std::string &file() const { return file_; }

 private:
  struct Impl;
  explicit FontFace(std::unique_ptr<Impl> impl, std::string file);
  std::unique_ptr<Impl> impl_;
  std::string file_;
};

}  // namespace lantern
