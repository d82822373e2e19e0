// RAII owners for the few OpenGL objects the renderer uses. Each owns one GL name and deletes it
// in its destructor; they must be destroyed while the context that made them is current.
#pragma once

#include <utility>

#include "core/render/gl/gl_functions.h"

namespace lantern {

// Generic owner: Deleter is a function deleting one name (e.g. glDeleteProgram wrapped).
template <void (*Delete)(GLuint)>
class GlName {
 public:
  GlName() = default;
  explicit GlName(GLuint name) : name_(name) {}
  ~GlName() { reset(); }
  GlName(GlName &&o) noexcept : name_(std::exchange(o.name_, 0)) {}
  GlName &operator=(GlName &&o) noexcept {
    if (this != &o) {
      reset();
      name_ = std::exchange(o.name_, 0);
    }
    return *this;
  }
  GlName(const GlName &) = delete;
  GlName &operator=(const GlName &) = delete;

  GLuint get() const { return name_; }
  void reset() {
    if (name_) Delete(name_);
    name_ = 0;
  }

 private:
  GLuint name_ = 0;
};

inline void delete_program(GLuint n) {
  gl().glDeleteProgram(n);
}
inline void delete_shader(GLuint n) {
  gl().glDeleteShader(n);
}
inline void delete_buffer(GLuint n) {
  gl().glDeleteBuffers(1, &n);
}
inline void delete_vertex_array(GLuint n) {
  gl().glDeleteVertexArrays(1, &n);
}
inline void delete_framebuffer(GLuint n) {
  gl().glDeleteFramebuffers(1, &n);
}
inline void delete_renderbuffer(GLuint n) {
  gl().glDeleteRenderbuffers(1, &n);
}

using GlProgram = GlName<delete_program>;
using GlShader = GlName<delete_shader>;
using GlBuffer = GlName<delete_buffer>;
using GlVertexArray = GlName<delete_vertex_array>;
using GlFramebuffer = GlName<delete_framebuffer>;
using GlRenderbuffer = GlName<delete_renderbuffer>;

}  // namespace lantern
