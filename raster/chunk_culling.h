#pragma once
// Per-face CPU culling of SceneBuffers chunks and the multi-draw of the survivors, shared by every renderer that
// draws a scene upload from a point.
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "raster/gl_functions.h"
#include "raster/scene_buffers.h"

namespace hemibake {

// Slack on chunk-box tests: covers float rounding of positions stored relative to the scene centre.
inline float chunkBoundsSlack(const SceneBuffers& scene) { return static_cast<float>(1e-6 * scene.sceneDiagonalM()); }

// Largest value of plane·(p − eye) over the box: the box lies outside the half-space when it is negative.
inline float maxAlongPlane(const glm::vec3& plane, const glm::vec3& boundsMin, const glm::vec3& boundsMax,
                           const glm::vec3& eye) {
    const glm::vec3 corner(plane.x >= 0.0f ? boundsMax.x : boundsMin.x, plane.y >= 0.0f ? boundsMax.y : boundsMin.y,
                           plane.z >= 0.0f ? boundsMax.z : boundsMin.z);
    return glm::dot(plane, corner - eye);
}

// Smallest value of plane·(p − eye) over the box: the box lies inside the half-space when it is positive.
inline float minAlongPlane(const glm::vec3& plane, const glm::vec3& boundsMin, const glm::vec3& boundsMax,
                           const glm::vec3& eye) {
    return -maxAlongPlane(-plane, boundsMin, boundsMax, eye);
}

// A test may add this bit to the faces it returns: the mask holds for the whole subtree (no need to descend).
inline constexpr std::uint8_t kSubtreeSettled = 0x80;

// Visits the chunk tree (SceneBuffers::chunkTree) from node n down with a face mask that only shrinks:
// `test(n, node, faces)` returns the faces the subtree can still reach; where that is none, at a leaf, or where the test
// marked it kSubtreeSettled, `assign(node, faces)` hands the mask to the node's chunks. One box test culls (or settles)
// a whole subtree.
template <class Test, class Assign>
void cullChunkTree(std::span<const SceneBuffers::ChunkNode> tree, std::uint32_t n, std::uint8_t faces, Test& test,
                   Assign& assign) {
    const SceneBuffers::ChunkNode& node = tree[n];
    faces = test(n, node, faces);
    if (faces == 0 || (faces & kSubtreeSettled) || node.chunkCount == 1) {
        assign(node, std::uint8_t(faces & ~kSubtreeSettled));
        return;
    }
    cullChunkTree(tree, n + 1, faces, test, assign);
    cullChunkTree(tree, tree[n + 1].skip, faces, test, assign);
}

// The chunks one face draws, as the ranges of one glMultiDrawArrays: consecutive chunks merge into one range
// (fewer draws for llvmpipe to set up). Reuse across faces; clear() keeps the capacity.
struct ChunkRuns {
    std::vector<GLint> firsts;
    std::vector<GLsizei> counts;
    void clear() {
        firsts.clear();
        counts.clear();
    }
    void add(const SceneBuffers::Chunk& chunk) {
        if (!firsts.empty() && firsts.back() + counts.back() == chunk.firstVertex)
            counts.back() += chunk.vertexCount;
        else {
            firsts.push_back(chunk.firstVertex);
            counts.push_back(chunk.vertexCount);
        }
    }
    bool empty() const { return firsts.empty(); }
    void draw(const GlFunctions& gl) const {
        gl.MultiDrawArrays(GL_TRIANGLES, firsts.data(), counts.data(), static_cast<GLsizei>(firsts.size()));
    }
};

}  // namespace hemibake
