#pragma once
// A PatchMesh's element triangles on one GL context: uploaded once, drawn by every hemicube on that context.
//
// Positions are float relative to PatchMesh::origin (the scene centre), so precision depends on the scene's
// size, not on its distance from the world origin. Triangles are grouped by median splits into small,
// spatially tight chunks with bounding boxes, so a hemicube face draws only the chunks its frustum can see.
// Each triangle has its own three vertices carrying its element index (flat: the item-buffer id and the row
// of the radiance texture buffer) and its element's normal (to tell back faces in the vertex stage). (Shared, indexed vertices were tried: llvmpipe then runs the vertex shader
// over each multi-draw's whole index range, which costs more than 3 vertices per triangle; see
// docs/performance.md.)
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/islands.h"
#include "mesh/patches.h"
#include "raster/gl_object.h"

namespace hemibake {

// Light that varies inside elements, shown per fragment through lightmap UVs: a radiance-buffer fragment of element
// e shows elementRadiance[e] + scale[e] · layers[layer](u, v), bilinear. The final gather uses it for ray-traced
// direct light, whose hot spots and shadow edges are much finer than elements (a ceiling 5 cm above a light panel).
struct TexelLight {
    int atlasSize = 0;  // every layer is atlasSize² texels; corner UVs address it (a smaller atlas uses its corner)
    std::vector<std::vector<glm::vec3>> layers;           // per layer, atlasSize², row 0 at v = 0; W·m⁻²·sr⁻¹
    std::vector<std::array<glm::vec3, 3>> cornerUvLayer;  // per element, per corner: (u, v, layer); layer < 0: none
    std::vector<glm::vec3> scale;                         // per element (e.g. ρ and a normalisation)
};

class SceneBuffers {
public:
    // Smaller chunks cull tighter and cost more box tests: on level_clean's bake 8, 16 and 32 took the same time
    // (docs/performance.md, "Each chunk drawn once"); 16 draws 0.19 of the level per hemicube where 32 draws 0.26.
    static constexpr std::uint32_t kDefaultTrianglesPerChunk = 16;

    struct Chunk {
        glm::vec3 boundsMin;  // relative to origin()
        glm::vec3 boundsMax;
        GLint firstVertex;
        GLsizei vertexCount;
        float areaM2;  // of its triangles: how much an occluder it can be
    };

    // The median-split tree the chunks came from, depth-first: node i's chunks are [firstChunk, firstChunk +
    // chunkCount); an inner node's children are node i + 1 and node (i + 1).skip, and skip is the first node after
    // i's subtree. One box test can cull a whole subtree (a room's chunks behind one wall).
    struct ChunkNode {
        glm::vec3 boundsMin;  // relative to origin(), the union of its chunks' boxes
        glm::vec3 boundsMax;
        std::uint32_t firstChunk;
        std::uint32_t chunkCount;
        std::uint32_t skip;
    };

    // `context` must outlive this object; binds it while uploading.
    SceneBuffers(const GlContext& context, const PatchMesh& mesh,
                 std::uint32_t trianglesPerChunk = kDefaultTrianglesPerChunk);

    // Outgoing radiance per element, W·m⁻²·sr⁻¹ (= B/π for Lambertian elements). Starts at 0.
    void setElementRadiance(std::span<const glm::vec3> radiance);

    // Uploads `light` (its arrays sized to the elements, layers to atlasSize²); replaces any earlier one. Throws
    // GlError on a size mismatch or GL failure. Binds the context.
    void setTexelLight(const TexelLight& light);
    void clearTexelLight() { hasTexelLight_ = false; }  // radiance fragments show elementRadiance only
    bool hasTexelLight() const { return hasTexelLight_; }

    const GlContext& context() const { return *context_; }
    std::size_t elementCount() const { return elementCount_; }
    std::span<const Chunk> chunks() const { return chunks_; }
    std::span<const ChunkNode> chunkTree() const { return chunkTree_; }  // node 0 is the root
    // Element drawn as triangle k (a chunk holds triangles firstVertex/3 … (firstVertex + vertexCount)/3 − 1).
    std::span<const std::uint32_t> drawOrder() const { return order_; }
    const glm::dvec3& origin() const { return origin_; }
    double sceneDiagonalM() const { return sceneDiagonalM_; }
    // The elements' islands (by instance), floats from origin(): lengths that must stand above float rounding near a
    // point take its island's size, not the scene's (mesh/islands.h).
    const SceneIslands& islands() const { return islands_; }
    // Vertex array: attribute 0 position (vec3), 1 element index (uint), 2 element normal (packed vec4), 3 lightmap
    // (u, v, layer) once a TexelLight is set.
    GLuint vertexArray() const { return vertexArray_.id(); }
    GLuint radianceTexture() const { return radianceTexture_.id(); }  // RGB32F, per element
    GLuint texelLightTexture() const { return texelLightTexture_.id(); }  // 2D array, RGB32F (0 until set)
    GLuint texelLightScaleTexture() const { return texelLightScaleTexture_.id(); }  // RGB32F, per element

private:
    const GlContext* context_;
    std::size_t elementCount_ = 0;
    glm::dvec3 origin_{0.0};
    double sceneDiagonalM_ = 0.0;
    SceneIslands islands_;
    std::vector<Chunk> chunks_;
    std::vector<ChunkNode> chunkTree_;
    GlObject vertexBuffer_;
    GlObject vertexArray_;
    GlObject radianceBuffer_;
    GlObject radianceTexture_;
    std::vector<std::uint32_t> order_;  // element drawn as triangle k (vertices 3k … 3k + 2)
    bool hasTexelLight_ = false;
    GlObject texelLightUvBuffer_;  // attribute 3: (u, v, layer) per vertex
    GlObject texelLightTexture_;
    GlObject texelLightScaleBuffer_;
    GlObject texelLightScaleTexture_;
};

}  // namespace hemibake
