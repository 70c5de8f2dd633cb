// OpenGL 3.3 core entry points, linked through glvnd's libOpenGL (the vendor is picked by EGL).
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>
