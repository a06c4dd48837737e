#pragma once
// Per-face CPU culling of SceneBuffers chunks and the multi-draw of the survivors, shared by every renderer that
// draws a scene upload from a point.
#include <vector>

#include <glm/glm.hpp>

#include "raster/gl_functions.h"
#include "raster/scene_buffers.h"

namespace hemibake {

// Slack on chunk-box tests: covers float rounding of positions stored relative to the scene centre.
inline float chunkBoundsSlack(const SceneBuffers& scene) { return static_cast<float>(1e-6 * scene.sceneDiagonalM()); }

// Largest value of plane·(p − eye) over the chunk's box: the box lies outside the half-space when it is negative.
inline float maxAlongPlane(const glm::vec3& plane, const SceneBuffers::Chunk& chunk, const glm::vec3& eye) {
    const glm::vec3 corner(plane.x >= 0.0f ? chunk.boundsMax.x : chunk.boundsMin.x,
                           plane.y >= 0.0f ? chunk.boundsMax.y : chunk.boundsMin.y,
                           plane.z >= 0.0f ? chunk.boundsMax.z : chunk.boundsMin.z);
    return glm::dot(plane, corner - eye);
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
