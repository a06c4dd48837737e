#include "baker/lightmap/element_interpolation.h"

#include <algorithm>
#include <numeric>

namespace hemibake {

namespace {
std::uint64_t keyOf(std::uint32_t instance, std::uint32_t face) { return (std::uint64_t(instance) << 32) | face; }
}  // namespace

glm::dvec3 barycentric(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& p) {
    const glm::dvec3 v0 = b - a, v1 = c - a, v2 = p - a;
    const double d00 = glm::dot(v0, v0), d01 = glm::dot(v0, v1), d11 = glm::dot(v1, v1);
    const double d20 = glm::dot(v2, v0), d21 = glm::dot(v2, v1);
    const double denom = d00 * d11 - d01 * d01;
    if (!(std::abs(denom) > 0.0)) return glm::dvec3(1.0 / 3.0);
    const double v = (d11 * d20 - d01 * d21) / denom;
    const double w = (d00 * d21 - d01 * d20) / denom;
    return {1.0 - v - w, v, w};
}

ElementInterpolator::ElementInterpolator(const PatchMesh& mesh, const std::vector<glm::dvec3>& elementValues) : mesh_(mesh) {
    const ElementArrays& el = mesh.elements;
    vertexValue_.assign(el.vertices.size(), glm::dvec3(0.0));
    std::vector<double> weight(el.vertices.size(), 0.0);
    for (std::size_t e = 0; e < el.size(); ++e) {
        if (el.backSide[e]) continue;
        for (std::uint32_t v : el.triangles[e]) {
            vertexValue_[v] += elementValues[e] * el.areaM2[e];
            weight[v] += el.areaM2[e];
        }
    }
    for (std::size_t v = 0; v < vertexValue_.size(); ++v)
        if (weight[v] > 0.0) vertexValue_[v] /= weight[v];

    for (std::uint32_t e = 0; e < el.size(); ++e)
        if (!el.backSide[e]) sorted_.push_back(e);
    std::sort(sorted_.begin(), sorted_.end(), [&](std::uint32_t a, std::uint32_t b) {
        return keyOf(el.instance[a], el.sourceFace[a]) < keyOf(el.instance[b], el.sourceFace[b]);
    });
    sortedKey_.resize(sorted_.size());
    for (std::size_t i = 0; i < sorted_.size(); ++i) sortedKey_[i] = keyOf(el.instance[sorted_[i]], el.sourceFace[sorted_[i]]);
}

std::optional<std::uint32_t> ElementInterpolator::locate(std::uint32_t instance, std::uint32_t sourceFace,
                                                         const glm::dvec3& p) const {
    const std::uint64_t key = keyOf(instance, sourceFace);
    auto [lo, hi] = std::equal_range(sortedKey_.begin(), sortedKey_.end(), key);
    std::optional<std::uint32_t> best;
    double bestMin = -1e300;
    for (auto it = lo; it != hi; ++it) {
        const std::uint32_t e = sorted_[std::size_t(it - sortedKey_.begin())];
        const auto& t = mesh_.elements.triangles[e];
        const glm::dvec3 w = barycentric(mesh_.elements.vertices[t[0]], mesh_.elements.vertices[t[1]],
                                         mesh_.elements.vertices[t[2]], p);
        // The element whose smallest barycentric is largest contains p (or is nearest to containing it).
        const double m = std::min({w.x, w.y, w.z});
        if (m > bestMin) {
            bestMin = m;
            best = e;
        }
    }
    return best;
}

glm::dvec3 ElementInterpolator::valueAt(std::uint32_t element, const glm::dvec3& p) const {
    const auto& t = mesh_.elements.triangles[element];
    glm::dvec3 w = barycentric(mesh_.elements.vertices[t[0]], mesh_.elements.vertices[t[1]], mesh_.elements.vertices[t[2]], p);
    // Clamp to the triangle so points nudged just outside do not extrapolate.
    w = glm::max(w, glm::dvec3(0.0));
    w /= std::max(w.x + w.y + w.z, 1e-300);
    return w.x * vertexValue_[t[0]] + w.y * vertexValue_[t[1]] + w.z * vertexValue_[t[2]];
}

}  // namespace hemibake
