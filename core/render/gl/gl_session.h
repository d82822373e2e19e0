// The process's rendering session of one GL back end: one GL context and one sphere renderer,
// shared by every Lantern context of the process that uses that back end, and destroyed with
// the last of them.
//
// Thread-safety: none; GL contexts are per thread and Lantern is called from one thread.
#pragma once

#include <memory>
#include <string>
#include <thread>

#include "core/common/status.h"
#include "core/config/config.h"
#include "core/render/gl/gl_context.h"
#include "core/render/gl/sphere_renderer.h"

namespace lantern {

class GlSession {
 public:
  // The live session for `wanted` (kAuto: any live one), or a new one (create_gl_context). *out
  // is null with an OK status when the back end is none or kAuto found no GL; *passed_over then
  // says why each back end was passed over.
  static Status acquire(GlBackend wanted, const EglOptions &egl, std::shared_ptr<GlSession> *out,
                        std::string *passed_over);

  // Makes the context current (another library may have switched contexts) and gives the
  // renderer in *out. From a thread other than the one that created the session, a failure
  // says that the GL context belongs to that thread (it stays current there).
  Status renderer(SphereRenderer **out);
  const char *backend() const { return context_->backend(); }
  std::string description() const { return context_->description(); }

 private:
  GlSession() = default;
  std::unique_ptr<GlContext> context_;        // declared first: destroyed last
  std::unique_ptr<SphereRenderer> renderer_;  // needs the context alive to free GL objects
  std::thread::id owner_ = std::this_thread::get_id();  // the thread that created the context
};

// For tools and tests that need OpenGL: the session of `wanted` (kAuto: EGL or OSMesa) and its
// renderer, or a kGl status saying why there is none.
Status acquire_renderer(GlBackend wanted, std::shared_ptr<GlSession> *session,
                        SphereRenderer **renderer);

}  // namespace lantern
