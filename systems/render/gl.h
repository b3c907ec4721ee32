#pragma once
// The one place GL headers are included. Prototypes come straight from libOSMesa (no loader), and the
// macro must precede the first <GL/gl.h> anywhere in the translation unit.
#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>
