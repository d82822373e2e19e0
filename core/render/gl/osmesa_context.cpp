// GlContext back end: Mesa's off-screen OSMesa (llvmpipe on CPU). Removed from Mesa 25.1; EGL
// (egl_context.cpp) is the way forward, this stays for systems without a usable EGL.
// gl.h first: it asks GL/glext.h for the prototypes gl_functions.h takes its types from, and
// GL/osmesa.h would include GL/gl.h without them.
#include "core/render/gl/gl.h"
// clang-format off
#include <GL/osmesa.h>
// clang-format on

#include <array>
#include <string>

#include "core/render/gl/gl_context.h"
#include "core/render/gl/gl_functions.h"

namespace lantern {
namespace {

void *lookup_gl(const char *name) {
  return reinterpret_cast<void *>(OSMesaGetProcAddress(name));
}

class OsmesaContext final : public GlContext {
 public:
  explicit OsmesaContext(OSMesaContext ctx) : ctx_(ctx) {}
  ~OsmesaContext() override {
    if (&gl() == &functions_) set_current_gl_functions(nullptr);
    OSMesaDestroyContext(ctx_);
  }

  Status load() { return load_gl_functions(lookup_gl, &functions_); }

  Status make_current() override {
    // OSMesa insists on a color buffer; Lantern draws into its own FBOs, so 1x1 is enough.
    if (!OSMesaMakeCurrent(ctx_, dummy_.data(), GL_UNSIGNED_BYTE, 1, 1))
      return {StatusCode::kGl, "OSMesaMakeCurrent failed"};
    set_current_gl_functions(&functions_);
    return {};
  }

  const char *backend() const override { return "osmesa"; }

  std::string description() const override { return "OSMesa / " + gl_driver_text(functions_); }

 private:
  OSMesaContext ctx_;
  std::array<unsigned char, 4> dummy_{};
  GlFunctions functions_;
};

}  // namespace

Status create_osmesa_context(std::unique_ptr<GlContext> *out) {
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         0,
                         OSMESA_STENCIL_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         3,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         3,
                         0};
  OSMesaContext raw = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!raw)
    return {StatusCode::kGl,
            "OSMesaCreateContextAttribs failed: no OpenGL 3.3 core context from OSMesa"};
  auto ctx = std::make_unique<OsmesaContext>(raw);
  if (Status s = ctx->load(); !s.ok()) return s;
  if (Status s = ctx->make_current(); !s.ok()) return s;
  *out = std::move(ctx);
  return {};
}

}  // namespace lantern
