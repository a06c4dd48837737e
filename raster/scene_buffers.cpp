#include "raster/scene_buffers.h"

#include <algorithm>
#include <limits>
#include <cstddef>
#include <numeric>
#include <string>

namespace hemibake {

namespace {

struct Vertex {
    float position[3];  // relative to the mesh origin
    std::uint32_t element;
};
static_assert(sizeof(Vertex) == 16);

// 10 bits per axis interleaved: neighbours on the curve are neighbours in space, so consecutive runs of
// triangles make tight chunk bounds.
std::uint32_t mortonCode(const glm::dvec3& unit) {
    auto spread = [](std::uint32_t v) {
        v = (v | (v << 16)) & 0x030000FFu;
        v = (v | (v << 8)) & 0x0300F00Fu;
        v = (v | (v << 4)) & 0x030C30C3u;
        v = (v | (v << 2)) & 0x09249249u;
        return v;
    };
    auto quantise = [](double t) { return static_cast<std::uint32_t>(std::clamp(t, 0.0, 1.0) * 1023.0); };
    return spread(quantise(unit.x)) | (spread(quantise(unit.y)) << 1) | (spread(quantise(unit.z)) << 2);
}

}  // namespace

SceneBuffers::SceneBuffers(const GlContext& context, const PatchMesh& mesh, std::uint32_t trianglesPerChunk)
    : context_(&context), elementCount_(mesh.elements.size()), origin_(mesh.origin),
      sceneDiagonalM_(mesh.sceneDiagonalM) {
    const ElementArrays& elements = mesh.elements;
    if (elementCount_ >= 0xFFFFFFF0u) throw GlError("SceneBuffers: too many elements for 32-bit item ids");
    if (!(sceneDiagonalM_ > 0.0)) throw GlError("SceneBuffers: PatchMesh::sceneDiagonalM must be positive");
    if (trianglesPerChunk == 0) trianglesPerChunk = kDefaultTrianglesPerChunk;

    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (const glm::dvec3& v : elements.vertices) {
        lo = glm::min(lo, v);
        hi = glm::max(hi, v);
    }
    const glm::dvec3 extent = glm::max(hi - lo, glm::dvec3(1e-30));
    std::vector<std::uint32_t> codes(elementCount_);
    for (std::size_t e = 0; e < elementCount_; ++e) {
        const auto& t = elements.triangles[e];
        const glm::dvec3 c = (elements.vertices[t[0]] + elements.vertices[t[1]] + elements.vertices[t[2]]) / 3.0;
        codes[e] = mortonCode((c - lo) / extent);
    }
    std::vector<std::uint32_t> order(elementCount_);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return codes[a] < codes[b]; });

    std::vector<Vertex> vertices;
    vertices.reserve(3 * elementCount_);
    for (std::size_t first = 0; first < elementCount_; first += trianglesPerChunk) {
        const std::size_t last = std::min<std::size_t>(first + trianglesPerChunk, elementCount_);
        Chunk chunk{glm::vec3(std::numeric_limits<float>::infinity()), glm::vec3(-std::numeric_limits<float>::infinity()),
                    static_cast<GLint>(vertices.size()), static_cast<GLsizei>(3 * (last - first))};
        for (std::size_t k = first; k < last; ++k) {
            const std::uint32_t e = order[k];
            for (std::uint32_t vi : elements.triangles[e]) {
                const glm::vec3 p(elements.vertices[vi] - origin_);
                chunk.boundsMin = glm::min(chunk.boundsMin, p);
                chunk.boundsMax = glm::max(chunk.boundsMax, p);
                vertices.push_back(Vertex{{p.x, p.y, p.z}, e});
            }
        }
        chunks_.push_back(chunk);
    }

    auto bound = context.bind();
    const GlFunctions& gl = context.gl();
    vertexArray_ = GlObject(context, GlObjectKind::VertexArray);
    vertexBuffer_ = GlObject(context, GlObjectKind::Buffer);
    gl.BindVertexArray(vertexArray_.id());
    gl.BindBuffer(GL_ARRAY_BUFFER, vertexBuffer_.id());
    gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data(),
                  GL_STATIC_DRAW);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<const void*>(offsetof(Vertex, position)));
    gl.EnableVertexAttribArray(1);
    gl.VertexAttribIPointer(1, 1, GL_UNSIGNED_INT, sizeof(Vertex), reinterpret_cast<const void*>(offsetof(Vertex, element)));
    gl.BindVertexArray(0);

    radianceBuffer_ = GlObject(context, GlObjectKind::Buffer);
    radianceTexture_ = GlObject(context, GlObjectKind::Texture);
    const std::vector<glm::vec3> zeros(std::max<std::size_t>(elementCount_, 1), glm::vec3(0.0f));
    gl.BindBuffer(GL_TEXTURE_BUFFER, radianceBuffer_.id());
    gl.BufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(zeros.size() * sizeof(glm::vec3)), zeros.data(),
                  GL_DYNAMIC_DRAW);
    gl.BindTexture(GL_TEXTURE_BUFFER, radianceTexture_.id());
    gl.TexBuffer(GL_TEXTURE_BUFFER, GL_RGB32F, radianceBuffer_.id());
    gl.BindTexture(GL_TEXTURE_BUFFER, 0);
    gl.BindBuffer(GL_TEXTURE_BUFFER, 0);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
    gl.check(("SceneBuffers: uploading " + std::to_string(elementCount_) + " elements").c_str());
}

void SceneBuffers::setElementRadiance(std::span<const glm::vec3> radiance) {
    if (radiance.size() != elementCount_)
        throw GlError("SceneBuffers::setElementRadiance: got " + std::to_string(radiance.size()) +
                      " values for " + std::to_string(elementCount_) + " elements");
    if (radiance.empty()) return;
    auto bound = context_->bind();
    const GlFunctions& gl = context_->gl();
    gl.BindBuffer(GL_TEXTURE_BUFFER, radianceBuffer_.id());
    gl.BufferSubData(GL_TEXTURE_BUFFER, 0, static_cast<GLsizeiptr>(radiance.size_bytes()), radiance.data());
    gl.BindBuffer(GL_TEXTURE_BUFFER, 0);
    gl.check("SceneBuffers::setElementRadiance");
}

}  // namespace hemibake
