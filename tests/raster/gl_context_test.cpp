// raster/gl_context + gl_functions: OSMesa llvmpipe contexts, one per thread, bindings that restore.
#include <gtest/gtest.h>

#include <GL/osmesa.h>

#include <thread>

#include "raster/gl_context.h"

namespace hemibake {
namespace {

TEST(GlContext, IsCoreProfileWithClipControl) {
    GlContext context;
    EXPECT_GE(context.majorVersion() * 10 + context.minorVersion(), 33);
    EXPECT_NE(context.gl().ClipControl, nullptr);
    EXPECT_NE(context.rendererName().find("llvmpipe"), std::string::npos) << context.rendererName();
    // Nothing stays current after construction: no thread keeps a pointer to a context it does not use.
    EXPECT_EQ(OSMesaGetCurrentContext(), nullptr);
}

TEST(GlContext, BindingsNestAndRestoreThePreviousContext) {
    GlContext a, b;
    {
        auto boundA = a.bind();
        const OSMesaContext ctxA = OSMesaGetCurrentContext();
        ASSERT_NE(ctxA, nullptr);
        {
            auto boundB = b.bind();
            EXPECT_NE(OSMesaGetCurrentContext(), ctxA);
            { auto again = b.bind(); }  // re-binding the current context is a no-op...
            EXPECT_NE(OSMesaGetCurrentContext(), nullptr);  // ...and does not release it
        }
        EXPECT_EQ(OSMesaGetCurrentContext(), ctxA);
        GLint viewport[4] = {};
        a.gl().GetIntegerv(GL_VIEWPORT, viewport);
        EXPECT_NO_THROW(a.gl().check("after restoring"));
    }
    EXPECT_EQ(OSMesaGetCurrentContext(), nullptr);
}

TEST(GlContext, OneContextPerThreadWorksConcurrently) {
    int versions[2] = {};
    auto work = [&](int slot) {
        GlContext context;
        auto bound = context.bind();
        GLint major = 0;
        context.gl().GetIntegerv(GL_MAJOR_VERSION, &major);
        versions[slot] = major;
    };
    std::thread t0(work, 0), t1(work, 1);
    t0.join();
    t1.join();
    EXPECT_GE(versions[0], 3);
    EXPECT_EQ(versions[0], versions[1]);
}

TEST(GlFunctions, CheckReportsGlErrorsWithContext) {
    GlContext context;
    auto bound = context.bind();
    context.gl().Enable(0x1234);  // not a capability: GL_INVALID_ENUM
    try {
        context.gl().check("enabling nonsense");
        FAIL() << "expected GlError";
    } catch (const GlError& e) {
        EXPECT_NE(std::string(e.what()).find("enabling nonsense: GL error 0x0500"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace hemibake
