#pragma once
// Smooth values from the piecewise-constant element solution: each vertex takes the area-weighted mean of
// the elements around it, and a surface point interpolates its element's corners (Gouraud). The fast preset
// fills lightmap texels this way; the quality presets gather instead.
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "mesh/patches.h"

namespace hemibake {

class ElementInterpolator {
public:
    // `elementValues` per element (e.g. irradiance); only front-side elements are used (lightmaps store the
    // front side of double-sided surfaces).
    ElementInterpolator(const PatchMesh& mesh, const std::vector<glm::dvec3>& elementValues);

    // The element of (instance, glTF source triangle) that contains p (nearest if p is just outside all of them).
    std::optional<std::uint32_t> locate(std::uint32_t instance, std::uint32_t sourceFace, const glm::dvec3& p) const;
    // Vertex-interpolated value at p inside element e.
    glm::dvec3 valueAt(std::uint32_t element, const glm::dvec3& p) const;

private:
    const PatchMesh& mesh_;
    std::vector<glm::dvec3> vertexValue_;
    // Front elements sorted by (instance, sourceFace) with the start of each key's run.
    std::vector<std::uint32_t> sorted_;
    std::vector<std::uint64_t> sortedKey_;
};

// Barycentric coordinates of p's projection onto triangle (a, b, c).
glm::dvec3 barycentric(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& p);

}  // namespace hemibake
