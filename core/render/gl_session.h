// The process's rendering session: one GL context and one sphere renderer, shared by every
// Lantern context of the process and destroyed with the last of them.
//
// Thread-safety: none; OSMesa contexts are per thread and Lantern is called from one thread.
#pragma once

#include <memory>
#include <string>

#include "core/common/status.h"
#include "core/render/gl_context.h"
#include "core/render/sphere_renderer.h"

namespace lantern {

class GlSession {
 public:
  // The live session, or a new one, into *out. On failure returns kGl and leaves *out alone.
  static Status acquire(std::shared_ptr<GlSession> *out);

  // Makes the context current (another library may have switched contexts) and sets *out to the
  // renderer. On failure returns kGl and leaves *out alone.
  Status renderer(SphereRenderer **out);
  std::string description() const { return context_->description(); }

 private:
  GlSession() = default;
  std::unique_ptr<GlContext> context_;        // declared first: destroyed last
  std::unique_ptr<SphereRenderer> renderer_;  // needs the context alive to free GL objects
};

}  // namespace lantern
