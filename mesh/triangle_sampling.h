#pragma once
// Fixed, stratified points on an element's triangle, shared by everything that averages a field over elements
// (direct light, exposure): the same points everywhere, so their averages are comparable.
#include <algorithm>
#include <cmath>
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

// The barycentric weights (wa, wb) of a uniform point, from two uniforms in [0, 1), in sub-triangle `index` of the
// k² that forEachSubTriangleCentroid visits (same order; index < k²): one point in each of the k² is a stratified
// sample of the triangle.
inline glm::dvec2 pointInSubTriangle(int k, int index, double u1, double u2) {
    // Row i (first weight in [i/k, (i+1)/k]) holds k − i upright and k − i − 1 inverted sub-triangles, alternating;
    // 2ki − i² come before it.
    int i = 0;
    while (i + 1 < k && 2 * k * (i + 1) - (i + 1) * (i + 1) <= index) ++i;
    const int offset = index - (2 * k * i - i * i), j = offset / 2;
    const double s = 1.0 / double(k);
    glm::dvec2 p0(i * s, j * s), p1((i + 1) * s, j * s), p2(i * s, (j + 1) * s);
    if (offset % 2 == 1) p0 = glm::dvec2((i + 1) * s, (j + 1) * s);  // inverted: the corner opposite the upright's
    const double r = std::sqrt(u1);
    return (1.0 - r) * p0 + r * (1.0 - u2) * p1 + r * u2 * p2;
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
