#pragma once
// Per-face CPU culling of SceneBuffers chunks, shared by every renderer that draws a scene upload from a point.
#include <glm/glm.hpp>

#include "raster/scene_buffers.h"

namespace hemibake {

// Largest value of plane·(p − eye) over the chunk's box: the box lies outside the half-space when it is negative.
inline float maxAlongPlane(const glm::vec3& plane, const SceneBuffers::Chunk& chunk, const glm::vec3& eye) {
    const glm::vec3 corner(plane.x >= 0.0f ? chunk.boundsMax.x : chunk.boundsMin.x,
                           plane.y >= 0.0f ? chunk.boundsMax.y : chunk.boundsMin.y,
                           plane.z >= 0.0f ? chunk.boundsMax.z : chunk.boundsMin.z);
    return glm::dot(plane, corner - eye);
}

}  // namespace hemibake
