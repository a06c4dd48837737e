#pragma once
// Every GL entry point hemibake uses, loaded through OSMesaGetProcAddress into one table per context.
// libGL is never linked beside libOSMesa (its dispatch would swallow every call silently), so nothing here
// may call a gl* symbol directly: all calls go through a GlFunctions instance.
#include <stdexcept>
#include <string>

#ifdef GL_GLEXT_PROTOTYPES
#error "raster/ must not see GL prototypes: every entry point comes from OSMesaGetProcAddress"
#endif
#include <GL/glcorearb.h>

namespace hemibake {

// GL 1.1 pointer types spelled out: when <GL/gl.h> (via osmesa.h) comes first, glcorearb.h skips its 1.1 block.
using GlGenTexturesProc = void(APIENTRYP)(GLsizei n, GLuint* textures);
using GlDeleteTexturesProc = void(APIENTRYP)(GLsizei n, const GLuint* textures);
using GlBindTextureProc = void(APIENTRYP)(GLenum target, GLuint texture);
using GlDrawArraysProc = void(APIENTRYP)(GLenum mode, GLint first, GLsizei count);
using GlTexImage2DProc = void(APIENTRYP)(GLenum target, GLint level, GLint internalformat, GLsizei width,
                                         GLsizei height, GLint border, GLenum format, GLenum type, const void* pixels);
using GlTexParameteriProc = void(APIENTRYP)(GLenum target, GLenum pname, GLint param);

class GlError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// X-macro list: (member name, GL symbol suffix, pointer type).
#define HEMIBAKE_GL_FUNCTIONS(X)                                             \
    X(GetError, PFNGLGETERRORPROC)                                           \
    X(GetString, PFNGLGETSTRINGPROC)                                         \
    X(GetStringi, PFNGLGETSTRINGIPROC)                                       \
    X(GetIntegerv, PFNGLGETINTEGERVPROC)                                     \
    X(Enable, PFNGLENABLEPROC)                                               \
    X(Disable, PFNGLDISABLEPROC)                                             \
    X(Viewport, PFNGLVIEWPORTPROC)                                           \
    X(Scissor, PFNGLSCISSORPROC)                                             \
    X(ClipControl, PFNGLCLIPCONTROLPROC)                                     \
    X(DepthFunc, PFNGLDEPTHFUNCPROC)                                         \
    X(DepthMask, PFNGLDEPTHMASKPROC)                                         \
    X(ClearBufferuiv, PFNGLCLEARBUFFERUIVPROC)                               \
    X(ClearBufferfv, PFNGLCLEARBUFFERFVPROC)                                 \
    X(DrawBuffers, PFNGLDRAWBUFFERSPROC)                                     \
    X(ReadBuffer, PFNGLREADBUFFERPROC)                                       \
    X(ReadPixels, PFNGLREADPIXELSPROC)                                       \
    X(PixelStorei, PFNGLPIXELSTOREIPROC)                                     \
    X(Finish, PFNGLFINISHPROC)                                               \
    X(GenFramebuffers, PFNGLGENFRAMEBUFFERSPROC)                             \
    X(DeleteFramebuffers, PFNGLDELETEFRAMEBUFFERSPROC)                       \
    X(BindFramebuffer, PFNGLBINDFRAMEBUFFERPROC)                             \
    X(FramebufferRenderbuffer, PFNGLFRAMEBUFFERRENDERBUFFERPROC)             \
    X(CheckFramebufferStatus, PFNGLCHECKFRAMEBUFFERSTATUSPROC)               \
    X(GenRenderbuffers, PFNGLGENRENDERBUFFERSPROC)                           \
    X(DeleteRenderbuffers, PFNGLDELETERENDERBUFFERSPROC)                     \
    X(BindRenderbuffer, PFNGLBINDRENDERBUFFERPROC)                           \
    X(RenderbufferStorage, PFNGLRENDERBUFFERSTORAGEPROC)                     \
    X(GenTextures, GlGenTexturesProc)                                        \
    X(DeleteTextures, GlDeleteTexturesProc)                                  \
    X(BindTexture, GlBindTextureProc)                                        \
    X(TexImage2D, GlTexImage2DProc)                                          \
    X(TexParameteri, GlTexParameteriProc)                                    \
    X(TexImage3D, PFNGLTEXIMAGE3DPROC)                                       \
    X(DrawArrays, GlDrawArraysProc)                                          \
    X(ActiveTexture, PFNGLACTIVETEXTUREPROC)                                 \
    X(TexBuffer, PFNGLTEXBUFFERPROC)                                         \
    X(GenBuffers, PFNGLGENBUFFERSPROC)                                       \
    X(DeleteBuffers, PFNGLDELETEBUFFERSPROC)                                 \
    X(BindBuffer, PFNGLBINDBUFFERPROC)                                       \
    X(BufferData, PFNGLBUFFERDATAPROC)                                       \
    X(BufferSubData, PFNGLBUFFERSUBDATAPROC)                                 \
    X(GenVertexArrays, PFNGLGENVERTEXARRAYSPROC)                             \
    X(DeleteVertexArrays, PFNGLDELETEVERTEXARRAYSPROC)                       \
    X(BindVertexArray, PFNGLBINDVERTEXARRAYPROC)                             \
    X(EnableVertexAttribArray, PFNGLENABLEVERTEXATTRIBARRAYPROC)             \
    X(VertexAttribPointer, PFNGLVERTEXATTRIBPOINTERPROC)                     \
    X(VertexAttribIPointer, PFNGLVERTEXATTRIBIPOINTERPROC)                   \
    X(CreateShader, PFNGLCREATESHADERPROC)                                   \
    X(ShaderSource, PFNGLSHADERSOURCEPROC)                                   \
    X(CompileShader, PFNGLCOMPILESHADERPROC)                                 \
    X(GetShaderiv, PFNGLGETSHADERIVPROC)                                     \
    X(GetShaderInfoLog, PFNGLGETSHADERINFOLOGPROC)                           \
    X(DeleteShader, PFNGLDELETESHADERPROC)                                   \
    X(CreateProgram, PFNGLCREATEPROGRAMPROC)                                 \
    X(AttachShader, PFNGLATTACHSHADERPROC)                                   \
    X(LinkProgram, PFNGLLINKPROGRAMPROC)                                     \
    X(GetProgramiv, PFNGLGETPROGRAMIVPROC)                                   \
    X(GetProgramInfoLog, PFNGLGETPROGRAMINFOLOGPROC)                         \
    X(DeleteProgram, PFNGLDELETEPROGRAMPROC)                                 \
    X(UseProgram, PFNGLUSEPROGRAMPROC)                                       \
    X(GetUniformLocation, PFNGLGETUNIFORMLOCATIONPROC)                       \
    X(Uniform1i, PFNGLUNIFORM1IPROC)                                         \
    X(Uniform1f, PFNGLUNIFORM1FPROC)                                         \
    X(Uniform2f, PFNGLUNIFORM2FPROC)                                         \
    X(Uniform3f, PFNGLUNIFORM3FPROC)                                         \
    X(UniformMatrix3fv, PFNGLUNIFORMMATRIX3FVPROC)                           \
    X(UniformMatrix4fv, PFNGLUNIFORMMATRIX4FVPROC)                           \
    X(MultiDrawArrays, PFNGLMULTIDRAWARRAYSPROC)

struct GlFunctions {
#define HEMIBAKE_GL_MEMBER(name, type) type name = nullptr;
    HEMIBAKE_GL_FUNCTIONS(HEMIBAKE_GL_MEMBER)
#undef HEMIBAKE_GL_MEMBER

    // Loads every entry point; throws GlError naming the first one OSMesa does not provide.
    static GlFunctions load();

    // Throws GlError("<what>: GL error 0x....") if the GL error flag is set.
    void check(const char* what) const;
};

}  // namespace hemibake
