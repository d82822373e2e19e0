#include "core/render/gl_session.h"

namespace lantern {

std::shared_ptr<GlSession> GlSession::acquire(std::string *error) {
  static std::weak_ptr<GlSession> live;
  if (auto s = live.lock()) return s;
  std::shared_ptr<GlSession> s(new GlSession());
  s->context_ = create_gl_context(error);
  if (!s->context_) return nullptr;
  s->renderer_ = SphereRenderer::create(error);
  if (!s->renderer_) return nullptr;
  live = s;
  return s;
}

SphereRenderer *GlSession::renderer(std::string *error) {
  if (auto e = context_->make_current(); !e.empty()) {
    *error = e;
    return nullptr;
  }
  return renderer_.get();
}

}  // namespace lantern
