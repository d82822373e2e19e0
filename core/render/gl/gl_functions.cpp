#include "core/render/gl/gl_functions.h"

namespace lantern {
namespace {

const GlFunctions kUnloaded{};
const GlFunctions *current = &kUnloaded;

}  // namespace

Status load_gl_functions(GlProcLookup lookup, GlFunctions *out) {
  GlFunctions f;
#define LANTERN_GL_LOAD(name)                                 \
  f.name = reinterpret_cast<decltype(f.name)>(lookup(#name)); \
  if (!f.name) return {StatusCode::kGl, "the GL back end has no " #name};
  LANTERN_GL_FUNCTIONS(LANTERN_GL_LOAD)
#undef LANTERN_GL_LOAD
  *out = f;
  return {};
}

std::string gl_driver_text(const GlFunctions &f) {
  const auto text = [&f](GLenum name) {
    const GLubyte *s = f.glGetString ? f.glGetString(name) : nullptr;
    return s ? std::string(reinterpret_cast<const char *>(s)) : std::string("?");
  };
  return text(GL_RENDERER) + " / GL " + text(GL_VERSION);
}

const GlFunctions &gl() {
  return *current;
}

void set_current_gl_functions(const GlFunctions *functions) {
  current = functions ? functions : &kUnloaded;
}

}  // namespace lantern
