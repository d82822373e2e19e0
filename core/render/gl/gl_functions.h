// The OpenGL entry points Lantern's renderer calls, loaded at run time from whichever back end
// made the current context (EGL through eglGetProcAddress, OSMesa through
// OSMesaGetProcAddress), so that one build can carry both back ends and link neither libGL nor
// libOpenGL: each library exports its own gl* symbols, and a call bound at link time to one of
// them would reach a dispatch table the other back end never made current.
//
// Use: the renderer calls gl().glClear(...) etc. The table is the one of the context made
// current last (set_current_gl_functions, called by GlContext::make_current), mirroring GL's own
// current-context model. Thread-safety: like GL itself, one thread (Lantern is called from one).
#pragma once

#include <string>

#include "core/common/status.h"
#include "core/render/gl/gl.h"

// Every GL function the renderer uses; X(name) per function.
// clang-format off
#define LANTERN_GL_FUNCTIONS(X) \
  X(glAttachShader) \
  X(glBindBuffer) \
  X(glBindFramebuffer) \
  X(glBindRenderbuffer) \
  X(glBindVertexArray) \
  X(glBlendEquation) \
  X(glBufferData) \
  X(glCheckFramebufferStatus) \
  X(glClear) \
  X(glClearColor) \
  X(glClearDepth) \
  X(glColorMask) \
  X(glCompileShader) \
  X(glCreateProgram) \
  X(glCreateShader) \
  X(glDeleteBuffers) \
  X(glDeleteFramebuffers) \
  X(glDeleteProgram) \
  X(glDeleteRenderbuffers) \
  X(glDeleteShader) \
  X(glDeleteVertexArrays) \
  X(glDepthFunc) \
  X(glDepthMask) \
  X(glDisable) \
  X(glDrawArraysInstanced) \
  X(glEnable) \
  X(glEnableVertexAttribArray) \
  X(glFinish) \
  X(glFramebufferRenderbuffer) \
  X(glGenBuffers) \
  X(glGenFramebuffers) \
  X(glGenRenderbuffers) \
  X(glGenVertexArrays) \
  X(glGetError) \
  X(glGetIntegerv) \
  X(glGetProgramInfoLog) \
  X(glGetProgramiv) \
  X(glGetShaderInfoLog) \
  X(glGetShaderiv) \
  X(glGetString) \
  X(glGetUniformLocation) \
  X(glLinkProgram) \
  X(glPixelStorei) \
  X(glReadPixels) \
  X(glRenderbufferStorage) \
  X(glShaderSource) \
  X(glUniform1f) \
  X(glUniform1i) \
  X(glUniform2f) \
  X(glUniformMatrix4fv) \
  X(glUseProgram) \
  X(glVertexAttribDivisor) \
  X(glVertexAttribPointer) \
  X(glViewport)
// clang-format on

namespace lantern {

struct GlFunctions {
  // decltype of the prototype only: nothing here links against a GL library.
#define LANTERN_GL_POINTER(name) decltype(&::name) name = nullptr;
  LANTERN_GL_FUNCTIONS(LANTERN_GL_POINTER)
#undef LANTERN_GL_POINTER
};

// A back end's lookup: the address of a GL entry point by name, or null.
using GlProcLookup = void *(*)(const char *name);

// Fills *out through `lookup`; a kGl status naming the first entry point it lacks.
Status load_gl_functions(GlProcLookup lookup, GlFunctions *out);

// "<renderer> / GL <version>" of the context whose functions these are (current), for the
// back ends' descriptions.
std::string gl_driver_text(const GlFunctions &functions);

// The table of the context made current last (all null before any).
const GlFunctions &gl();
void set_current_gl_functions(const GlFunctions *functions);

}  // namespace lantern
