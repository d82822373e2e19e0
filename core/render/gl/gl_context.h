// The OpenGL context Lantern renders with, behind a small interface with two back ends: EGL
// (egl_context.cpp: a GPU, or Mesa's software device, headless) and OSMesa (osmesa_context.cpp:
// Mesa's off-screen library, gone from Mesa 25.1). Each is optional at build time
// (LANTERN_WITH_EGL / LANTERN_WITH_OSMESA); which one runs is chosen at run time
// (create_gl_context). GL entry points are loaded from the back end that made the context
// (gl_functions.h), so the renderer does not care which.
//
// Lantern renders into its own framebuffer objects, so a context only has to exist and be current.
// Thread-safety: a context is bound to the thread that made it current; use one thread.
#pragma once

#include <memory>
#include <string>

#include "core/common/status.h"
#include "core/config/config.h"

namespace lantern {

class GlContext {
 public:
  virtual ~GlContext() = default;
  GlContext() = default;
  GlContext(const GlContext &) = delete;
  GlContext &operator=(const GlContext &) = delete;

  // Makes the context current on the calling thread, with its GL functions (gl_functions.h).
  virtual Status make_current() = 0;
  // "egl" or "osmesa": what the stats line reports.
  virtual const char *backend() const = 0;
  // Human-readable back end and driver, e.g. "EGL (device 0, software) / llvmpipe ... / GL 4.5".
  virtual std::string description() const = 0;
};

// Where an EGL context goes. device >= 0: that EGL device, or failure. device < 0: the node's
// hardware devices, rank `local_rank` (the rank among those on the node) on device
// local_rank mod count, then Mesa's software device, then the surfaceless platform.
struct EglOptions {
  int device = -1;
  int local_rank = 0;
};

// Whether this build carries the back end (kAuto and kNone: always).
bool gl_backend_built(GlBackend backend);

// A context in *out of the back end `wanted` (kAuto: EGL) or, when that one fails, of the other;
// when both fail (or wanted is kNone) *out is null: no OpenGL, and the CPU raster draws. The
// reasons back ends were passed over go to *passed_over ("" when the first one worked).
Status create_gl_context(GlBackend wanted, const EglOptions &egl, std::unique_ptr<GlContext> *out,
                         std::string *passed_over);

// The back ends themselves (only where built).
Status create_egl_context(const EglOptions &options, std::unique_ptr<GlContext> *out);
Status create_osmesa_context(std::unique_ptr<GlContext> *out);

}  // namespace lantern
