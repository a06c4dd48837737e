#include "raster/gl_functions.h"

#include <GL/osmesa.h>

#include <cstdio>

namespace hemibake {

GlFunctions GlFunctions::load() {
    GlFunctions gl;
#define HEMIBAKE_GL_LOAD(name, type)                                                                  \
    gl.name = reinterpret_cast<type>(OSMesaGetProcAddress("gl" #name));                               \
    if (gl.name == nullptr) throw GlError("OSMesa does not provide gl" #name " (need OpenGL 4.5 core)");
    HEMIBAKE_GL_FUNCTIONS(HEMIBAKE_GL_LOAD)
#undef HEMIBAKE_GL_LOAD
    return gl;
}

void GlFunctions::check(const char* what) const {
    const GLenum error = GetError();
    if (error == GL_NO_ERROR) return;
    char code[16];
    std::snprintf(code, sizeof code, "0x%04X", error);
    throw GlError(std::string(what) + ": GL error " + code);
}

}  // namespace hemibake
