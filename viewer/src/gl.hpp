#pragma once
// OpenGL 3.3 core entry points. Mesa's libOpenGL exports them all, so they are declared through
// GL_GLEXT_PROTOTYPES rather than fetched by a loader; libglvnd dispatches every call to the
// current context, whether EGL (headless) or GLX (a GLFW window) made it.

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
