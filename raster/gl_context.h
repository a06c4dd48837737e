#pragma once
// An OSMesa (llvmpipe) OpenGL 4.5 core context with its own entry-point table.
//
// llvmpipe runs the vertex stage of one context on one thread, so hemibake uses one context per worker thread.
// A context is current only inside a Binding: binding on entry, restoring the thread's previous context on
// exit. Nothing stays current on a thread between calls, so a context can be destroyed (or handed to another
// thread) without leaving a dangling "current context" behind in some worker's thread-local state.
// A context must not be bound by two threads at the same time.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "raster/gl_functions.h"

namespace hemibake {

class GlContext {
public:
    // OpenGL 4.5 core; falls back to 3.3 core (which then needs ARB_clip_control for GlFunctions to load). The
    // first context of the process sets LP_NUM_THREADS=0 (llvmpipe rasterizes on the calling thread; see the .cpp).
    // Throws GlError; thread-safe.
    GlContext();
    ~GlContext();
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;

    class Binding {
    public:
        ~Binding();
        Binding(const Binding&) = delete;
        Binding& operator=(const Binding&) = delete;

    private:
        friend class GlContext;
        explicit Binding(const GlContext& context);
        void* previousContext_ = nullptr;  // OSMesaContext to restore; null when already current
        void* previousBuffer_ = nullptr;
        int previousWidth_ = 0, previousHeight_ = 0;
        bool restore_ = false;
    };

    // Makes the context current on the calling thread until the Binding dies (a no-op if already current).
    [[nodiscard]] Binding bind() const { return Binding(*this); }

    const GlFunctions& gl() const { return gl_; }
    int majorVersion() const { return majorVersion_; }
    int minorVersion() const { return minorVersion_; }
    const std::string& rendererName() const { return rendererName_; }
    bool hasExtension(const std::string& name) const;

private:
    void* context_ = nullptr;  // OSMesaContext (opaque here so users need not include osmesa.h)
    // OSMesa insists on a default framebuffer; all rendering goes to FBOs, so one pixel is enough.
    mutable std::array<std::uint32_t, 1> dummyBuffer_{};
    GlFunctions gl_;
    int majorVersion_ = 0, minorVersion_ = 0;
    std::string rendererName_;
    std::vector<std::string> extensions_;
};

}  // namespace hemibake
