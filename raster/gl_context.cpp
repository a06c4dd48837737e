#include "raster/gl_context.h"

#include <GL/osmesa.h>

#include <algorithm>
#include <cstdlib>
#include <mutex>

namespace hemibake {

namespace {

// llvmpipe's rasterizer threads are shared by every context of the process. With two contexts rendering and
// reading back at once (one per worker), Mesa 22.3 crashed inside glReadPixels in about one bake in ten once the
// occlusion pass made every hemicube flush several short depth-only scenes (WallOnSlabs, CI stop 24; 0 crashes in
// 30 runs with the threads off). hemibake already renders on one context per core, and rasterizing on the calling
// thread also measured 10-15 % faster on small bakes, so the threads are always off. Mesa reads the variable when
// the first context is created; call_once keeps the write ahead of every context any thread creates.
void turnOffLlvmpipeRasterizerThreads() {
    static std::once_flag once;
    std::call_once(once, [] { setenv("LP_NUM_THREADS", "0", 1); });
}

OSMesaContext createContext(int major, int minor) {
    const int attributes[] = {OSMESA_FORMAT,        OSMESA_RGBA,
                              OSMESA_DEPTH_BITS,    0,  // depth lives in hemibake's own FBOs
                              OSMESA_STENCIL_BITS,  0,
                              OSMESA_ACCUM_BITS,    0,
                              OSMESA_PROFILE,       OSMESA_CORE_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION, major,
                              OSMESA_CONTEXT_MINOR_VERSION, minor,
                              0};
    return OSMesaCreateContextAttribs(attributes, nullptr);
}

}  // namespace

GlContext::GlContext() {
    turnOffLlvmpipeRasterizerThreads();
    OSMesaContext context = createContext(4, 5);
    if (context == nullptr) context = createContext(3, 3);
    if (context == nullptr) throw GlError("OSMesaCreateContextAttribs failed for OpenGL 4.5 and 3.3 core profiles");
    context_ = context;
    try {
        Binding bound(*this);
        gl_ = GlFunctions::load();
        gl_.GetIntegerv(GL_MAJOR_VERSION, &majorVersion_);
        gl_.GetIntegerv(GL_MINOR_VERSION, &minorVersion_);
        const auto* renderer = reinterpret_cast<const char*>(gl_.GetString(GL_RENDERER));
        rendererName_ = renderer != nullptr ? renderer : "unknown";
        GLint extensionCount = 0;
        gl_.GetIntegerv(GL_NUM_EXTENSIONS, &extensionCount);
        for (GLint i = 0; i < extensionCount; ++i)
            extensions_.emplace_back(reinterpret_cast<const char*>(gl_.GetStringi(GL_EXTENSIONS, static_cast<GLuint>(i))));
        gl_.check("GlContext: querying the context");
    } catch (...) {
        OSMesaDestroyContext(context);
        throw;
    }
}

bool GlContext::hasExtension(const std::string& name) const {
    return std::find(extensions_.begin(), extensions_.end(), name) != extensions_.end();
}

GlContext::~GlContext() {
    // If this thread still has us current (only possible inside a Binding's lifetime), release first so the
    // thread's state never points at a destroyed context.
    if (OSMesaGetCurrentContext() == static_cast<OSMesaContext>(context_)) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
}

GlContext::Binding::Binding(const GlContext& context) {
    const OSMesaContext target = static_cast<OSMesaContext>(context.context_);
    const OSMesaContext previous = OSMesaGetCurrentContext();
    if (previous == target) return;
    if (previous != nullptr) {
        GLint format = 0;
        void* buffer = nullptr;
        if (OSMesaGetColorBuffer(previous, &previousWidth_, &previousHeight_, &format, &buffer)) {
            previousBuffer_ = buffer;
            previousContext_ = previous;
        }
    }
    if (!OSMesaMakeCurrent(target, context.dummyBuffer_.data(), GL_UNSIGNED_BYTE, 1, 1))
        throw GlError("OSMesaMakeCurrent failed");
    restore_ = true;
}

GlContext::Binding::~Binding() {
    if (!restore_) return;
    if (previousContext_ != nullptr)
        OSMesaMakeCurrent(static_cast<OSMesaContext>(previousContext_), previousBuffer_, GL_UNSIGNED_BYTE,
                          previousWidth_, previousHeight_);
    else
        OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
}

}  // namespace hemibake
