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
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/patches.h"
#include "raster/gl_object.h"

namespace hemibake {

class SceneBuffers {
public:
    static constexpr std::uint32_t kDefaultTrianglesPerChunk = 32;

    struct Chunk {
        glm::vec3 boundsMin;  // relative to origin()
        glm::vec3 boundsMax;
        GLint firstVertex;
        GLsizei vertexCount;
    };

    // `context` must outlive this object; binds it while uploading.
    SceneBuffers(const GlContext& context, const PatchMesh& mesh,
                 std::uint32_t trianglesPerChunk = kDefaultTrianglesPerChunk);

    // Outgoing radiance per element, W·m⁻²·sr⁻¹ (= B/π for Lambertian elements). Starts at 0.
    void setElementRadiance(std::span<const glm::vec3> radiance);

    const GlContext& context() const { return *context_; }
    std::size_t elementCount() const { return elementCount_; }
    std::span<const Chunk> chunks() const { return chunks_; }
    const glm::dvec3& origin() const { return origin_; }
    double sceneDiagonalM() const { return sceneDiagonalM_; }
    // Vertex array: attribute 0 position (vec3), 1 element index (uint), 2 element normal (packed vec4).
    GLuint vertexArray() const { return vertexArray_.id(); }
    GLuint radianceTexture() const { return radianceTexture_.id(); }  // RGB32F, per element

private:
    const GlContext* context_;
    std::size_t elementCount_ = 0;
    glm::dvec3 origin_{0.0};
    double sceneDiagonalM_ = 0.0;
    std::vector<Chunk> chunks_;
    GlObject vertexBuffer_;
    GlObject vertexArray_;
    GlObject radianceBuffer_;
    GlObject radianceTexture_;
};

}  // namespace hemibake
