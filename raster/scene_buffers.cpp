#include "raster/scene_buffers.h"

#include <algorithm>
#include <limits>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <string>

#include "mesh/frame_math.h"

namespace hemibake {

namespace {

// Signed 10-bit components: enough to tell which side of its plane the eye is on, except within ~0.1° of
// edge-on, where the triangle covers no pixel anyway.
std::uint32_t packNormal(const glm::vec3& n) {
    auto component = [](float v) {
        return static_cast<std::uint32_t>(static_cast<std::int32_t>(std::lround(std::clamp(v, -1.0f, 1.0f) * 511.0f))) & 0x3FFu;
    };
    return component(n.x) | (component(n.y) << 10) | (component(n.z) << 20);
}

// Median splits along the longest axis of the centroid bounds until a run fits in one chunk: leaves come out
// in depth-first order, so chunks are spatially tight (good culling) and neighbouring chunks are usually
// visible together (their vertex runs merge into one range of the multi-draw). Appends the split tree's nodes
// (bounds left for the caller: they need the chunks' boxes).
void splitIntoChunks(std::vector<std::uint32_t>& order, std::size_t first, std::size_t last,
                     const std::vector<glm::dvec3>& centroids, std::size_t maxPerChunk,
                     std::vector<SceneBuffers::ChunkNode>& tree) {
    const std::size_t node = tree.size();
    tree.push_back(SceneBuffers::ChunkNode{glm::vec3(0.0f), glm::vec3(0.0f), static_cast<std::uint32_t>(first / maxPerChunk),
                                           static_cast<std::uint32_t>((last - first + maxPerChunk - 1) / maxPerChunk), 0});
    if (last - first > maxPerChunk) {
        glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
        for (std::size_t k = first; k < last; ++k) {
            lo = glm::min(lo, centroids[order[k]]);
            hi = glm::max(hi, centroids[order[k]]);
        }
        const int axis = largestComponent(hi - lo);
        // Split on a multiple of the chunk size so that every leaf but the last is full.
        const std::size_t half = first + ((last - first) / maxPerChunk + 1) / 2 * maxPerChunk;
        std::nth_element(order.begin() + first, order.begin() + half, order.begin() + last,
                         [&](std::uint32_t a, std::uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
        splitIntoChunks(order, first, half, centroids, maxPerChunk, tree);
        splitIntoChunks(order, half, last, centroids, maxPerChunk, tree);
    }
    tree[node].skip = static_cast<std::uint32_t>(tree.size());
}

}  // namespace

SceneBuffers::SceneBuffers(const GlContext& context, const PatchMesh& mesh, std::uint32_t trianglesPerChunk)
    : context_(&context), elementCount_(mesh.elements.size()), origin_(mesh.origin),
      sceneDiagonalM_(mesh.sceneDiagonalM), islands_(SceneIslands::ofElements(mesh.elements, mesh.origin)) {
    const ElementArrays& elements = mesh.elements;
    if (elementCount_ >= 0xFFFFFFF0u) throw GlError("SceneBuffers: too many elements for 32-bit item ids");
    if (!(sceneDiagonalM_ > 0.0)) throw GlError("SceneBuffers: PatchMesh::sceneDiagonalM must be positive");
    if (trianglesPerChunk == 0) trianglesPerChunk = kDefaultTrianglesPerChunk;

    std::vector<glm::dvec3> centroids(elementCount_);
    for (std::size_t e = 0; e < elementCount_; ++e) {
        const auto& t = elements.triangles[e];
        centroids[e] = (elements.vertices[t[0]] + elements.vertices[t[1]] + elements.vertices[t[2]]) / 3.0;
    }
    std::vector<std::uint32_t> order(elementCount_);
    std::iota(order.begin(), order.end(), 0u);
    if (elementCount_ > 0) splitIntoChunks(order, 0, elementCount_, centroids, trianglesPerChunk, chunkTree_);
    order_ = order;

    struct Vertex {
        glm::vec3 position;  // relative to the mesh origin
        std::uint32_t element;
        std::uint32_t normal;  // the element's normal, GL_INT_2_10_10_10_REV
    };
    static_assert(sizeof(Vertex) == 20);
    std::vector<Vertex> vertices;
    vertices.reserve(3 * elementCount_);
    for (std::size_t first = 0; first < elementCount_; first += trianglesPerChunk) {
        const std::size_t last = std::min<std::size_t>(first + trianglesPerChunk, elementCount_);
        Chunk chunk{glm::vec3(std::numeric_limits<float>::infinity()), glm::vec3(-std::numeric_limits<float>::infinity()),
                    static_cast<GLint>(vertices.size()), static_cast<GLsizei>(3 * (last - first)), 0.0f};
        for (std::size_t k = first; k < last; ++k) {
            const std::uint32_t e = order[k];
            const std::uint32_t normal = packNormal(elements.normal[e]);
            chunk.areaM2 += static_cast<float>(elements.areaM2[e]);
            for (std::uint32_t vi : elements.triangles[e]) {
                const glm::vec3 p(elements.vertices[vi] - origin_);
                chunk.boundsMin = glm::min(chunk.boundsMin, p);
                chunk.boundsMax = glm::max(chunk.boundsMax, p);
                vertices.push_back(Vertex{p, e, normal});
            }
        }
        chunks_.push_back(chunk);
    }
    // Children follow their parent in the tree: bounds from the leaves up.
    for (std::size_t n = chunkTree_.size(); n-- > 0;) {
        ChunkNode& node = chunkTree_[n];
        if (node.chunkCount == 1) {
            node.boundsMin = chunks_[node.firstChunk].boundsMin;
            node.boundsMax = chunks_[node.firstChunk].boundsMax;
        } else {
            const ChunkNode& left = chunkTree_[n + 1];
            const ChunkNode& right = chunkTree_[left.skip];
            node.boundsMin = glm::min(left.boundsMin, right.boundsMin);
            node.boundsMax = glm::max(left.boundsMax, right.boundsMax);
        }
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
    gl.EnableVertexAttribArray(2);
    gl.VertexAttribPointer(2, 4, GL_INT_2_10_10_10_REV, GL_TRUE, sizeof(Vertex), reinterpret_cast<const void*>(offsetof(Vertex, normal)));
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

void SceneBuffers::setTexelLight(const TexelLight& light) {
    const std::size_t texels = std::size_t(std::max(light.atlasSize, 0)) * std::size_t(std::max(light.atlasSize, 0));
    if (light.cornerUvLayer.size() != elementCount_ || light.scale.size() != elementCount_ || light.layers.empty() ||
        texels == 0)
        throw GlError("SceneBuffers::setTexelLight: arrays do not match the " + std::to_string(elementCount_) + " elements");
    std::vector<glm::vec3> image;
    image.reserve(texels * light.layers.size());
    for (const std::vector<glm::vec3>& layer : light.layers) {
        if (layer.size() != texels) throw GlError("SceneBuffers::setTexelLight: a layer is not atlasSize² texels");
        image.insert(image.end(), layer.begin(), layer.end());
    }
    std::vector<glm::vec3> uvLayer;
    uvLayer.reserve(3 * elementCount_);
    for (const std::uint32_t e : order_)
        for (const glm::vec3& corner : light.cornerUvLayer[e]) uvLayer.push_back(corner);

    auto bound = context_->bind();
    const GlFunctions& gl = context_->gl();
    if (!hasTexelLight_) {
        texelLightUvBuffer_ = GlObject(*context_, GlObjectKind::Buffer);
        texelLightTexture_ = GlObject(*context_, GlObjectKind::Texture);
        texelLightScaleBuffer_ = GlObject(*context_, GlObjectKind::Buffer);
        texelLightScaleTexture_ = GlObject(*context_, GlObjectKind::Texture);
    }
    gl.BindVertexArray(vertexArray_.id());
    gl.BindBuffer(GL_ARRAY_BUFFER, texelLightUvBuffer_.id());
    gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(uvLayer.size() * sizeof(glm::vec3)), uvLayer.data(), GL_STATIC_DRAW);
    gl.EnableVertexAttribArray(3);
    gl.VertexAttribPointer(3, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
    gl.BindVertexArray(0);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);

    gl.BindTexture(GL_TEXTURE_2D_ARRAY, texelLightTexture_.id());
    gl.TexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_RGB32F, light.atlasSize, light.atlasSize, GLsizei(light.layers.size()), 0,
                  GL_RGB, GL_FLOAT, image.data());
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl.BindTexture(GL_TEXTURE_2D_ARRAY, 0);

    gl.BindBuffer(GL_TEXTURE_BUFFER, texelLightScaleBuffer_.id());
    gl.BufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(light.scale.size() * sizeof(glm::vec3)), light.scale.data(),
                  GL_STATIC_DRAW);
    gl.BindTexture(GL_TEXTURE_BUFFER, texelLightScaleTexture_.id());
    gl.TexBuffer(GL_TEXTURE_BUFFER, GL_RGB32F, texelLightScaleBuffer_.id());
    gl.BindTexture(GL_TEXTURE_BUFFER, 0);
    gl.BindBuffer(GL_TEXTURE_BUFFER, 0);
    gl.check(("SceneBuffers::setTexelLight: " + std::to_string(light.layers.size()) + " layers of " +
              std::to_string(light.atlasSize) + "²").c_str());
    hasTexelLight_ = true;
}

}  // namespace hemibake
