#include "raster/cube_map_renderer.h"

#include <string>

#include "raster/chunk_culling.h"
#include "raster/reversed_z.h"

namespace hemibake {

namespace {

// Same vertex stage as the hemicube's (hemicube.cpp), minus the half-face transform: back-facing triangles
// are pushed back by 2^-20 of their depth so the side facing the eye wins ties between the two sides of a
// double-sided surface. The vector to the eye is interpolated (it is affine in the triangle, so the
// perspective-correct interpolation is exact) to give each texel its hit distance.
const char* kCubeMapVertexShader = R"(#version 330 core
layout(location = 0) in vec3 positionRelOrigin;
layout(location = 1) in uint elementId;
layout(location = 2) in vec3 elementNormal;
uniform vec3 eyeRelOrigin;
uniform mat3 faceRows;   // rows: right, up, forward of this face
uniform float nearM;
flat out uint element;
out vec3 fromEye;
void main() {
    vec3 toEye = eyeRelOrigin - positionRelOrigin;
    vec3 v = faceRows * -toEye;
    bool backFacing = dot(elementNormal, toEye) < 0.0;
    gl_Position = vec4(v.x, v.y, backFacing ? nearM * (1.0 - 1.0 / 1048576.0) : nearM, v.z);
    element = elementId;
    fromEye = -toEye;
}
)";

const char* kCubeMapFragmentShader = R"(#version 330 core
flat in uint element;
in vec3 fromEye;
uniform samplerBuffer elementRadiance;
layout(location = 0) out vec4 radiance;
void main() {
    float distance = length(fromEye);
    radiance = gl_FrontFacing ? vec4(texelFetch(elementRadiance, int(element)).rgb, distance)
                              : vec4(0.0, 0.0, 0.0, -distance);
}
)";

CubeFaceBasis makeFace(glm::dvec3 forward, glm::dvec3 up) { return {forward, glm::cross(forward, up), up}; }

}  // namespace

const CubeFaceBasis& cubeFaceBasis(int face) {
    static const std::array<CubeFaceBasis, CubeMapImage::kFaceCount> faces = {
        makeFace({1, 0, 0}, {0, 1, 0}),  makeFace({-1, 0, 0}, {0, 1, 0}), makeFace({0, 1, 0}, {0, 0, 1}),
        makeFace({0, -1, 0}, {0, 0, 1}), makeFace({0, 0, 1}, {0, 1, 0}),  makeFace({0, 0, -1}, {0, 1, 0})};
    return faces.at(std::size_t(face));
}

glm::dvec3 CubeMapImage::direction(int face, int i, int j) const {
    const CubeFaceBasis& b = cubeFaceBasis(face);
    const double s = -1.0 + (2.0 * i + 1.0) / resolution, t = -1.0 + (2.0 * j + 1.0) / resolution;
    return b.forward + s * b.right + t * b.up;
}

CubeMapRenderer::CubeMapRenderer(const SceneBuffers& scene, int resolution)
    : scene_(&scene), resolution_(resolution), nearPlaneM_(kNearPlanePerDiagonal * scene.sceneDiagonalM()) {
    if (resolution < 1 || resolution > 4096)
        throw GlError("CubeMapRenderer: resolution must be in [1, 4096], got " + std::to_string(resolution));
    const GlContext& context = scene.context();
    if (context.majorVersion() * 10 + context.minorVersion() < 45 && !context.hasExtension("GL_ARB_clip_control"))
        throw GlError("CubeMapRenderer needs OpenGL 4.5 or GL_ARB_clip_control (reversed-Z)");
    auto bound = context.bind();
    const GlFunctions& gl = context.gl();
    const int width = 3 * resolution, height = 2 * resolution;

    colorBuffer_ = GlObject(context, GlObjectKind::Renderbuffer);
    gl.BindRenderbuffer(GL_RENDERBUFFER, colorBuffer_.id());
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, width, height);
    depthBuffer_ = GlObject(context, GlObjectKind::Renderbuffer);
    gl.BindRenderbuffer(GL_RENDERBUFFER, depthBuffer_.id());
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
    gl.BindRenderbuffer(GL_RENDERBUFFER, 0);
    framebuffer_ = GlObject(context, GlObjectKind::Framebuffer);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_.id());
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colorBuffer_.id());
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depthBuffer_.id());
    const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        throw GlError("CubeMapRenderer: atlas framebuffer " + std::to_string(width) + "x" + std::to_string(height) +
                      " incomplete (status " + std::to_string(status) + ")");

    program_ = compileProgram(context, "cube map radiance", kCubeMapVertexShader, kCubeMapFragmentShader);
    eyeUniform_ = gl.GetUniformLocation(program_.id(), "eyeRelOrigin");
    faceRowsUniform_ = gl.GetUniformLocation(program_.id(), "faceRows");
    nearUniform_ = gl.GetUniformLocation(program_.id(), "nearM");
    radianceUniform_ = gl.GetUniformLocation(program_.id(), "elementRadiance");
    gl.UseProgram(program_.id());
    gl.Uniform1i(radianceUniform_, 0);
    gl.UseProgram(0);
    gl.check(("CubeMapRenderer: creating the R=" + std::to_string(resolution) + " atlas").c_str());
    runs_.firsts.reserve(scene.chunks().size());
    runs_.counts.reserve(scene.chunks().size());
}

void CubeMapRenderer::render(const glm::dvec3& position, glm::vec3 skyRadiance, CubeMapImage& out) {
    const GlContext& context = scene_->context();
    auto bound = context.bind();
    const GlFunctions& gl = context.gl();
    const glm::vec3 eye(position - scene_->origin());

    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_.id());
    const GLenum drawBuffer = GL_COLOR_ATTACHMENT0;
    gl.DrawBuffers(1, &drawBuffer);
    beginReversedZPass(gl);
    const GLfloat sky[4] = {skyRadiance.x, skyRadiance.y, skyRadiance.z, 0.0f};
    gl.ClearBufferfv(GL_COLOR, 0, sky);
    gl.Enable(GL_SCISSOR_TEST);  // guard-band rasterisers may otherwise spill into a neighbouring face

    gl.UseProgram(program_.id());
    gl.Uniform3f(eyeUniform_, eye.x, eye.y, eye.z);
    gl.Uniform1f(nearUniform_, static_cast<float>(nearPlaneM_));
    gl.BindVertexArray(scene_->vertexArray());
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_BUFFER, scene_->radianceTexture());

    // Per face, the chunks inside the face's frustum (four side planes through the eye; the slack covers float
    // rounding of positions relative to the scene centre), merged into runs of one multi-draw.
    const auto chunks = scene_->chunks();
    const float slack = chunkBoundsSlack(*scene_);
    lastChunksDrawn_ = 0;
    for (int face = 0; face < CubeMapImage::kFaceCount; ++face) {
        const CubeFaceBasis& b = cubeFaceBasis(face);
        const glm::vec3 f(b.forward), r(b.right), u(b.up);
        const glm::vec3 planes[4] = {f - r, f + r, f - u, f + u};
        runs_.clear();
        // Down the chunk tree (leaves come in chunk order, so runs merge as before); a box outside drops its subtree.
        auto inFrustum = [&](std::uint32_t, const SceneBuffers::ChunkNode& node, std::uint8_t faceMask) {
            for (const glm::vec3& plane : planes)
                if (maxAlongPlane(plane, node.boundsMin, node.boundsMax, eye) < -slack) return std::uint8_t(0);
            return faceMask;
        };
        auto addChunk = [&](const SceneBuffers::ChunkNode& node, std::uint8_t faceMask) {
            if (faceMask == 0) return;
            ++lastChunksDrawn_;
            runs_.add(chunks[node.firstChunk]);
        };
        if (!chunks.empty()) cullChunkTree(scene_->chunkTree(), 0, std::uint8_t(1), inFrustum, addChunk);
        if (runs_.empty()) continue;
        const GLfloat rows[9] = {r.x, r.y, r.z, u.x, u.y, u.z, f.x, f.y, f.z};
        gl.UniformMatrix3fv(faceRowsUniform_, 1, GL_TRUE, rows);
        const GLint x = (face % 3) * resolution_, y = (face / 3) * resolution_;
        gl.Viewport(x, y, resolution_, resolution_);
        gl.Scissor(x, y, resolution_, resolution_);
        runs_.draw(gl);
    }
    gl.BindVertexArray(0);
    gl.UseProgram(0);

    out.resolution = resolution_;
    out.pixels.resize(std::size_t(out.atlasWidth()) * std::size_t(out.atlasHeight()));
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl.ReadPixels(0, 0, out.atlasWidth(), out.atlasHeight(), GL_RGBA, GL_FLOAT, out.pixels.data());
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.check("CubeMapRenderer::render");
}

}  // namespace hemibake
