#include "core/render/gl/gl_context.h"

#include "core/config/enum_names.h"

namespace lantern {

bool gl_backend_built(GlBackend backend) {
  switch (backend) {
    case GlBackend::kEgl:
#ifdef LANTERN_HAVE_EGL
      return true;
#else
      return false;
#endif
    case GlBackend::kOsmesa:
#ifdef LANTERN_HAVE_OSMESA
      return true;
#else
      return false;
#endif
    case GlBackend::kAuto:
    case GlBackend::kNone:
      return true;
  }
  return false;
}

namespace {

Status create_one(GlBackend backend, const EglOptions &egl, std::unique_ptr<GlContext> *out) {
  if (!gl_backend_built(backend))
    return {StatusCode::kGl, std::string("this Lantern was built without ") +
                                 (backend == GlBackend::kEgl ? "EGL (LANTERN_WITH_EGL)"
                                                             : "OSMesa (LANTERN_WITH_OSMESA)")};
#ifdef LANTERN_HAVE_EGL
  if (backend == GlBackend::kEgl) return create_egl_context(egl, out);
#endif
#ifdef LANTERN_HAVE_OSMESA
  if (backend == GlBackend::kOsmesa) return create_osmesa_context(out);
#endif
  static_cast<void>(egl);
  return {StatusCode::kInternal, "no such GL back end"};
}

}  // namespace

Status create_gl_context(GlBackend wanted, const EglOptions &egl, std::unique_ptr<GlContext> *out,
                         std::string *passed_over) {
  out->reset();
  passed_over->clear();
  if (wanted == GlBackend::kNone) return {};
  // The one asked for first, then the others: a back end that fails is passed over, never fatal.
  const GlBackend first = wanted == GlBackend::kOsmesa ? GlBackend::kOsmesa : GlBackend::kEgl;
  const GlBackend second = first == GlBackend::kEgl ? GlBackend::kOsmesa : GlBackend::kEgl;
  for (const GlBackend b : {first, second}) {
    const Status s = create_one(b, egl, out);
    if (s.ok()) return s;
    *passed_over += (passed_over->empty() ? "" : "; ") + std::string(name_of(b)) + ": " + s.message;
  }
  return {};  // no GL at all: the CPU raster draws every scene
}

}  // namespace lantern
