#pragma once
// The depth convention every hemibake view renders with: reversed-Z (depth = near/distance, cleared to 0, nearer
// wins with GL_GREATER) and [0, 1] clip depth, so float depth keeps the same relative precision at every distance
// and the far plane can be infinite. Back faces are never culled: each renderer decides what they show.
#include "raster/gl_functions.h"

namespace hemibake {

// Sets that state on the bound framebuffer and clears its depth; leaves the scissor test off (so colour clears
// that follow reach every pixel) and colour untouched.
inline void beginReversedZPass(const GlFunctions& gl) {
    gl.ClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    gl.Disable(GL_CULL_FACE);
    gl.Disable(GL_SCISSOR_TEST);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_GREATER);
    gl.DepthMask(GL_TRUE);
    const GLfloat farDepth = 0.0f;
    gl.ClearBufferfv(GL_DEPTH, 0, &farDepth);
}

}  // namespace hemibake
