// The OpenGL context Lantern renders with, behind a small interface so that another back end
// (EGL with a surfaceless/device platform, once OSMesa is gone from Mesa 25.1) can replace OSMesa
// without touching the renderer.
//
// Lantern renders into its own framebuffer objects, so a context only has to exist and be current.
// Thread-safety: a context is bound to the thread that made it current; use one thread.
#pragma once

#include <memory>
#include <string>

#include "core/common/status.h"

namespace lantern {

class GlContext {
 public:
  virtual ~GlContext() = default;
  GlContext() = default;
  GlContext(const GlContext &) = delete;
  GlContext &operator=(const GlContext &) = delete;

  // Makes the context current on the calling thread. OK or kGl.
  virtual Status make_current() = 0;
  // Human-readable back end and driver, e.g. "OSMesa 22.3.6 / llvmpipe (LLVM 15, 256 bits)".
  virtual std::string description() const = 0;
};

// Creates the process's rendering context (OpenGL >= 3.3 core), current on the calling thread,
// into *out. On failure returns kGl and leaves *out alone. The current back end is OSMesa.
Status create_gl_context(std::unique_ptr<GlContext> *out);

}  // namespace lantern
