#pragma once
// Fixed, stratified points on an element's triangle, shared by everything that averages a field over elements
// (direct light, exposure): the same points everywhere, so their averages are comparable.
#include <algorithm>
#include <cstddef>

#include <glm/glm.hpp>

#include "mesh/patches.h"

namespace hemibake {

// Visits the centroids of the k² congruent sub-triangles of a triangle (k(k+1)/2 upright, k(k−1)/2 inverted), in
// a fixed order, as barycentric weights (wa, wb) of its first two vertices (the third gets 1 − wa − wb). Their
// mean is exact for any field linear over the triangle.
template <class Visit>
void forEachSubTriangleCentroid(int k, const Visit& visit) {
    for (int i = 0; i < k; ++i)
        for (int j = 0; i + j < k; ++j) {
            visit((i + 1.0 / 3.0) / k, (j + 1.0 / 3.0) / k);
            if (i + j + 2 <= k) visit((i + 2.0 / 3.0) / k, (j + 2.0 / 3.0) / k);
        }
}

// The element's whole triangle, m² (ElementArrays::areaM2 may be less: only the exposed part counts there,
// baker/exposed_area.h). Computed as mesh/subdivision.cpp does, so untouched elements match bit for bit.
inline double triangleArea(const ElementArrays& el, std::size_t e) {
    const auto& tri = el.triangles[e];
    const glm::dvec3 a = el.vertices[tri[0]], b = el.vertices[tri[1]], c = el.vertices[tri[2]];
    return 0.5 * glm::length(glm::cross(b - a, c - a));
}

// The point of element e with barycentric weights (wa, wb) of its first two vertices (as visited above).
inline glm::dvec3 pointOnElement(const ElementArrays& el, std::size_t e, double wa, double wb) {
    const auto& tri = el.triangles[e];
    return wa * el.vertices[tri[0]] + wb * el.vertices[tri[1]] + (1.0 - wa - wb) * el.vertices[tri[2]];
}

// Element e's longest edge, m (what subdivision bisects).
inline double longestEdgeM(const ElementArrays& el, std::size_t e) {
    double longest = 0.0;
    for (std::size_t k = 0; k < 3; ++k)
        longest = std::max(longest, glm::length(el.vertices[el.triangles[e][k]] - el.vertices[el.triangles[e][(k + 1) % 3]]));
    return longest;
}

// The distance from element e's centroid to its farthest corner, m: a refinement region of this radius around the
// centroid covers the element's refined faces, not its neighbours' (whose centroids lie further out).
inline double farthestCornerM(const ElementArrays& el, std::size_t e) {
    double radius = 0.0;
    for (std::size_t k = 0; k < 3; ++k) radius = std::max(radius, glm::length(el.vertices[el.triangles[e][k]] - el.centroid[e]));
    return radius;
}

}  // namespace hemibake
