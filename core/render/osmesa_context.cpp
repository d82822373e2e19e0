// GlContext back end: Mesa's off-screen OSMesa (llvmpipe on CPU).
#include <GL/osmesa.h>

#include <array>
#include <string>
#include <vector>

#include "core/render/gl.h"
#include "core/render/gl_context.h"

namespace lantern {
namespace {

class OsmesaContext final : public GlContext {
 public:
  explicit OsmesaContext(OSMesaContext ctx) : ctx_(ctx) {}
  ~OsmesaContext() override { OSMesaDestroyContext(ctx_); }

  Status make_current() override {
    // OSMesa insists on a color buffer; Lantern draws into its own FBOs, so 1x1 is enough.
    if (!OSMesaMakeCurrent(ctx_, dummy_.data(), GL_UNSIGNED_BYTE, 1, 1))
      return {StatusCode::kGl, "OSMesaMakeCurrent failed"};
    return {};
  }

  std::string description() const override {
    const auto *renderer = reinterpret_cast<const char *>(glGetString(GL_RENDERER));
    const auto *version = reinterpret_cast<const char *>(glGetString(GL_VERSION));
    return std::string("OSMesa / ") + (renderer ? renderer : "?") + " / GL " +
           (version ? version : "?");
  }

 private:
  OSMesaContext ctx_;
  std::array<unsigned char, 4> dummy_{};
};

}  // namespace

Status create_gl_context(std::unique_ptr<GlContext> *out) {
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
  if (Status s = ctx->make_current(); !s.ok()) return s;
  *out = std::move(ctx);
  return {};
}

}  // namespace lantern
