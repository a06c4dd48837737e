#include "raster/lightmapped_renderer.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "raster/gl_object.h"
#include "raster/reversed_z.h"

namespace hemibake {

namespace {

// Same reversed-Z projection as the hemicube: clip.z = near, clip.w = distance along the view axis.
const char* kLightmappedVertexShader = R"(#version 330 core
layout(location = 0) in vec3 positionRelEye;
layout(location = 1) in vec2 lightmapUv;
uniform mat3 viewRows;        // rows: right, up, forward
uniform vec2 inverseTanHalf;  // 1/tan(half fov) along x and y
uniform float nearM;
out vec2 uv;
void main() {
    vec3 v = viewRows * positionRelEye;
    gl_Position = vec4(v.x * inverseTanHalf.x, v.y * inverseTanHalf.y, nearM, v.z);
    uv = lightmapUv;
}
)";

const char* kLightmappedFragmentShader = R"(#version 330 core
in vec2 uv;
uniform sampler2D radianceAtlas;
uniform bool doubleSided;
layout(location = 0) out vec4 radiance;
void main() {
    radiance = (gl_FrontFacing || doubleSided) ? vec4(texture(radianceAtlas, uv).rgb, 1.0) : vec4(0.0, 0.0, 0.0, 1.0);
}
)";

struct Vertex {
    glm::vec3 positionRelEye;
    glm::vec2 uv;
};

}  // namespace

std::vector<glm::vec3> renderLightmapped(const GlContext& context, const std::vector<LightmappedBatch>& batches,
                                         const PinholeView& view, glm::vec3 background, int samplesPerAxis) {
    if (view.width < 1 || view.height < 1 || samplesPerAxis < 1)
        throw std::invalid_argument("renderLightmapped: image size and samples per axis must be positive");
    if (!(view.yfovRadians > 0.0 && view.yfovRadians < 3.14) || !(view.nearM > 0.0))
        throw std::invalid_argument("renderLightmapped: field of view must be in (0, π) and the near plane positive");
    const glm::dvec3 forward = glm::normalize(view.forward);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, view.up));
    const glm::dvec3 up = glm::cross(right, forward);
    if (!(glm::length(right) > 0.5)) throw std::invalid_argument("renderLightmapped: up is parallel to forward");

    const auto binding = context.bind();
    const GlFunctions& gl = context.gl();
    const int width = view.width * samplesPerAxis, height = view.height * samplesPerAxis;

    GlObject color(context, GlObjectKind::Renderbuffer), depth(context, GlObjectKind::Renderbuffer);
    gl.BindRenderbuffer(GL_RENDERBUFFER, color.id());
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, width, height);
    gl.BindRenderbuffer(GL_RENDERBUFFER, depth.id());
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
    gl.BindRenderbuffer(GL_RENDERBUFFER, 0);
    GlObject framebuffer(context, GlObjectKind::Framebuffer);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color.id());
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth.id());
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw GlError("renderLightmapped: " + std::to_string(width) + "×" + std::to_string(height) +
                      " float framebuffer is incomplete");
    gl.check("renderLightmapped: framebuffer");

    const GlObject program = compileProgram(context, "lightmapped view", kLightmappedVertexShader, kLightmappedFragmentShader);
    gl.UseProgram(program.id());
    const float rows[9] = {float(right.x), float(up.x), float(forward.x),  // column-major: columns are x, y, z
                           float(right.y), float(up.y), float(forward.y),
                           float(right.z), float(up.z), float(forward.z)};
    gl.UniformMatrix3fv(gl.GetUniformLocation(program.id(), "viewRows"), 1, GL_FALSE, rows);
    const double tanHalfY = std::tan(0.5 * view.yfovRadians);
    const double tanHalfX = tanHalfY * double(view.width) / double(view.height);
    gl.Uniform2f(gl.GetUniformLocation(program.id(), "inverseTanHalf"), float(1.0 / tanHalfX), float(1.0 / tanHalfY));
    gl.Uniform1f(gl.GetUniformLocation(program.id(), "nearM"), float(view.nearM));
    gl.Uniform1i(gl.GetUniformLocation(program.id(), "radianceAtlas"), 0);
    const GLint doubleSidedLocation = gl.GetUniformLocation(program.id(), "doubleSided");

    gl.Viewport(0, 0, width, height);
    beginReversedZPass(gl);
    const float sky[4] = {background.x, background.y, background.z, 0.0f};
    gl.ClearBufferfv(GL_COLOR, 0, sky);

    GlObject vertexArray(context, GlObjectKind::VertexArray);
    gl.BindVertexArray(vertexArray.id());
    for (const LightmappedBatch& batch : batches) {
        if (batch.positions.size() != batch.uvs.size() || batch.positions.size() % 3 != 0 || !batch.radiance ||
            batch.atlasSize < 1 || batch.radiance->size() != std::size_t(batch.atlasSize) * std::size_t(batch.atlasSize))
            throw std::invalid_argument("renderLightmapped: a batch's positions, UVs and atlas do not match");
        if (batch.positions.empty()) continue;
        std::vector<Vertex> vertices(batch.positions.size());
        for (std::size_t i = 0; i < vertices.size(); ++i)
            vertices[i] = {glm::vec3(batch.positions[i] - view.position), batch.uvs[i]};

        GlObject texture(context, GlObjectKind::Texture);
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_2D, texture.id());
        gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
        gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, batch.atlasSize, batch.atlasSize, 0, GL_RGB, GL_FLOAT,
                      batch.radiance->data());
        // Bilinear, as engines sample lightmaps; the bake dilates charts into their padding for this.
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        gl.Uniform1i(doubleSidedLocation, batch.doubleSided ? 1 : 0);

        GlObject buffer(context, GlObjectKind::Buffer);
        gl.BindBuffer(GL_ARRAY_BUFFER, buffer.id());
        gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(Vertex)), vertices.data(), GL_STATIC_DRAW);
        gl.EnableVertexAttribArray(0);
        gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<const void*>(0));
        gl.EnableVertexAttribArray(1);
        gl.VertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                               reinterpret_cast<const void*>(offsetof(Vertex, uv)));
        gl.DrawArrays(GL_TRIANGLES, 0, GLsizei(vertices.size()));
        gl.Finish();  // the texture and buffer die with this iteration
        gl.check("renderLightmapped: drawing a batch");
    }

    std::vector<glm::vec4> pixels(std::size_t(width) * std::size_t(height));
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, pixels.data());
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindVertexArray(0);
    gl.UseProgram(0);
    gl.check("renderLightmapped: readback");

    // Box filter, and GL's bottom-up rows to the image's top-down ones.
    std::vector<glm::vec3> image(std::size_t(view.width) * std::size_t(view.height));
    const double inverseSamples = 1.0 / double(samplesPerAxis * samplesPerAxis);
    for (int y = 0; y < view.height; ++y)
        for (int x = 0; x < view.width; ++x) {
            glm::dvec3 sum(0.0);
            for (int sy = 0; sy < samplesPerAxis; ++sy)
                for (int sx = 0; sx < samplesPerAxis; ++sx) {
                    const int glRow = height - 1 - (y * samplesPerAxis + sy);
                    const glm::vec4& p = pixels[std::size_t(glRow) * std::size_t(width) + std::size_t(x * samplesPerAxis + sx)];
                    sum += glm::dvec3(p.x, p.y, p.z);
                }
            image[std::size_t(y) * std::size_t(view.width) + std::size_t(x)] = glm::vec3(sum * inverseSamples);
        }
    return image;
}

}  // namespace hemibake
