#include "core/render/gl/gl_session.h"

#include <map>

#include "core/config/enum_names.h"

namespace lantern {
namespace {

// The live session of each back end ("egl", "osmesa").
std::map<std::string, std::weak_ptr<GlSession>> &live_sessions() {
  static std::map<std::string, std::weak_ptr<GlSession>> live;
  return live;
}

}  // namespace

Status GlSession::acquire(GlBackend wanted, const EglOptions &egl, std::shared_ptr<GlSession> *out,
                          std::string *passed_over) {
  out->reset();
  passed_over->clear();
  if (wanted == GlBackend::kNone) return {};
  auto &live = live_sessions();
  for (const char *name : {"egl", "osmesa"}) {
    const bool fits =
        wanted == GlBackend::kAuto || (wanted == GlBackend::kEgl) == (std::string(name) == "egl");
    if (auto s = live[name].lock(); s && fits) {
      *out = s;
      return {};
    }
  }
  std::shared_ptr<GlSession> s(new GlSession());
  if (Status st = create_gl_context(wanted, egl, &s->context_, passed_over); !st.ok()) return st;
  if (!s->context_) return {};  // auto found no GL
  if (Status st = SphereRenderer::create(&s->renderer_); !st.ok()) return st;
  live[s->context_->backend()] = s;
  *out = s;
  return {};
}

Status GlSession::renderer(SphereRenderer **out) {
  *out = nullptr;
  if (Status s = context_->make_current(); !s.ok()) {
    if (std::this_thread::get_id() != owner_)
      s.message +=
          "; the OpenGL context of a Lantern context belongs to the thread that opened "
          "it (lantern_open), where it stays current: call lantern_execute from that "
          "thread (or use gl: none, the CPU raster, which has no such tie)";
    return s;
  }
  *out = renderer_.get();
  return {};
}

Status acquire_renderer(GlBackend wanted, std::shared_ptr<GlSession> *session,
                        SphereRenderer **renderer) {
  *renderer = nullptr;
  std::string passed_over;
  if (Status s = GlSession::acquire(wanted, EglOptions{}, session, &passed_over); !s.ok()) return s;
  if (!*session) return {StatusCode::kGl, "no OpenGL back end: " + passed_over};
  if (wanted != GlBackend::kAuto && std::string((*session)->backend()) != name_of(wanted))
    return {StatusCode::kGl, std::string("no ") + name_of(wanted) + " context: " + passed_over};
  return (*session)->renderer(renderer);
}

}  // namespace lantern
