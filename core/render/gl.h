// OpenGL declarations. OSMesa exports every core entry point, so Lantern links them directly
// instead of loading function pointers.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>
