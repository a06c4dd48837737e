#include "raster/gl_object.h"

#include <string>

namespace hemibake {

GlObject::GlObject(const GlContext& context, GlObjectKind kind) : context_(&context), kind_(kind) {
    const GlFunctions& gl = context.gl();
    switch (kind) {
        case GlObjectKind::Buffer: gl.GenBuffers(1, &id_); break;
        case GlObjectKind::Texture: gl.GenTextures(1, &id_); break;
        case GlObjectKind::Renderbuffer: gl.GenRenderbuffers(1, &id_); break;
        case GlObjectKind::Framebuffer: gl.GenFramebuffers(1, &id_); break;
        case GlObjectKind::VertexArray: gl.GenVertexArrays(1, &id_); break;
        case GlObjectKind::Program: id_ = gl.CreateProgram(); break;
    }
    if (id_ == 0) throw GlError("GlObject: creating a GL object failed");
}

void GlObject::reset() noexcept {
    if (id_ == 0 || context_ == nullptr) return;
    try {
        auto bound = context_->bind();
        const GlFunctions& gl = context_->gl();
        switch (kind_) {
            case GlObjectKind::Buffer: gl.DeleteBuffers(1, &id_); break;
            case GlObjectKind::Texture: gl.DeleteTextures(1, &id_); break;
            case GlObjectKind::Renderbuffer: gl.DeleteRenderbuffers(1, &id_); break;
            case GlObjectKind::Framebuffer: gl.DeleteFramebuffers(1, &id_); break;
            case GlObjectKind::VertexArray: gl.DeleteVertexArrays(1, &id_); break;
            case GlObjectKind::Program: gl.DeleteProgram(id_); break;
        }
    } catch (...) {
        // Binding failed: the context is unusable and takes its objects with it when destroyed.
    }
    id_ = 0;
}

namespace {

GLuint compileShader(const GlFunctions& gl, std::string_view name, GLenum stage, const char* source) {
    const GLuint shader = gl.CreateShader(stage);
    gl.ShaderSource(shader, 1, &source, nullptr);
    gl.CompileShader(shader);
    GLint ok = GL_FALSE;
    gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
        char log[4096] = {};
        gl.GetShaderInfoLog(shader, sizeof log, nullptr, log);
        gl.DeleteShader(shader);
        throw GlError(std::string(name) + (stage == GL_VERTEX_SHADER ? ": vertex" : ": fragment") +
                      " shader does not compile: " + log);
    }
    return shader;
}

}  // namespace

GlObject compileProgram(const GlContext& context, std::string_view name, const char* vertexSource,
                        const char* fragmentSource) {
    const GlFunctions& gl = context.gl();
    GlObject program(context, GlObjectKind::Program);
    const GLuint vertex = compileShader(gl, name, GL_VERTEX_SHADER, vertexSource);
    GLuint fragment = 0;
    try {
        fragment = compileShader(gl, name, GL_FRAGMENT_SHADER, fragmentSource);
    } catch (...) {
        gl.DeleteShader(vertex);
        throw;
    }
    gl.AttachShader(program.id(), vertex);
    gl.AttachShader(program.id(), fragment);
    gl.LinkProgram(program.id());
    gl.DeleteShader(vertex);  // flagged for deletion; freed with the program
    gl.DeleteShader(fragment);
    GLint ok = GL_FALSE;
    gl.GetProgramiv(program.id(), GL_LINK_STATUS, &ok);
    if (ok != GL_TRUE) {
        char log[4096] = {};
        gl.GetProgramInfoLog(program.id(), sizeof log, nullptr, log);
        throw GlError(std::string(name) + ": program does not link: " + log);
    }
    return program;
}

}  // namespace hemibake
