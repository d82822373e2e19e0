// OpenGL declarations: types, constants and prototypes. The prototypes are only used for their
// types (gl_functions.h loads every entry point from the back end at run time); nothing links
// against a GL library.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>
