// FontFace in a build without FreeType and fontconfig (LANTERN_WITH_TEXT=OFF, or the libraries
// missing): every entry point says so, so that a scene asking for text is a configuration error.
#include "core/finish/overlays/font_face.h"

namespace lantern {
namespace {

Status no_text() {
  return {StatusCode::kConfig,
          "this build of Lantern has no overlay text (labels, legend, axes): it was built "
          "without FreeType and fontconfig (LANTERN_WITH_TEXT=OFF, or libfreetype-dev and "
          "libfontconfig-dev missing)"};
}

}  // namespace

struct FontFace::Impl {};

bool text_available() {
  return false;
}

Status find_font_file(const std::string &, std::string *) {
  return no_text();
}

Status FontFace::open(const std::string &, std::unique_ptr<FontFace> *) {
  return no_text();
}

FontFace::FontFace(std::unique_ptr<Impl> impl, std::string file)
    : impl_(std::move(impl)), file_(std::move(file)) {}
FontFace::~FontFace() = default;

TextMask FontFace::render(const std::string &, int) {
  return {};
}
int FontFace::measure(const std::string &, int) {
  return 0;
}

}  // namespace lantern
