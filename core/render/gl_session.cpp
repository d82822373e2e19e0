#include "core/render/gl_session.h"

namespace lantern {

Status GlSession::acquire(std::shared_ptr<GlSession> *out) {
  static std::weak_ptr<GlSession> live;
  if (auto s = live.lock()) {
    *out = std::move(s);
    return {};
  }
  std::shared_ptr<GlSession> s(new GlSession());
  if (Status st = create_gl_context(&s->context_); !st.ok()) return st;
  if (Status st = SphereRenderer::create(&s->renderer_); !st.ok()) return st;
  live = s;
  *out = std::move(s);
  return {};
}

Status GlSession::renderer(SphereRenderer **out) {
  if (Status s = context_->make_current(); !s.ok()) return s;
  *out = renderer_.get();
  return {};
}

}  // namespace lantern
