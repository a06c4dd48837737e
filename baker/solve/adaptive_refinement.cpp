#include "baker/solve/adaptive_refinement.h"
#include "mesh/triangle_sampling.h"

#include <algorithm>
#include <unordered_map>


namespace hemibake {

RefinementRequest findRadiosityDiscontinuities(const PatchMesh& mesh, const RadiositySolution& solution, double threshold,
                                               double targetSizeM) {
    const ElementArrays& el = mesh.elements;
    std::vector<double> b(el.size());
    double meanB = 0.0, area = 0.0;
    for (std::size_t e = 0; e < el.size(); ++e) {
        const glm::dvec3 v = solution.displayRadiosity(mesh, e);
        b[e] = v.x + v.y + v.z;
        meanB += b[e] * el.areaM2[e];
        area += el.areaM2[e];
    }
    meanB = area > 0.0 ? meanB / area : 0.0;
    // The floor keeps near-black regions, where relative differences are noise, from refining.
    const double floor = 0.01 * meanB;

    std::vector<std::uint8_t> marked(el.size(), 0);
    std::unordered_map<std::uint64_t, std::uint32_t> firstOfEdge;
    firstOfEdge.reserve(el.size() * 2);
    for (std::uint32_t e = 0; e < el.size(); ++e)
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v0 = el.triangles[e][std::size_t(k)], v1 = el.triangles[e][std::size_t((k + 1) % 3)];
            const std::uint64_t key = (std::uint64_t(std::min(v0, v1)) << 32) | std::max(v0, v1);
            auto [it, inserted] = firstOfEdge.emplace(key, e);
            if (inserted) continue;
            const std::uint32_t other = it->second;
            if (std::abs(b[e] - b[other]) > threshold * (std::max(b[e], b[other]) + floor)) marked[e] = marked[other] = 1;
        }

    RefinementRequest request;
    for (std::size_t e = 0; e < el.size(); ++e) {
        if (!marked[e]) continue;
        if (longestEdgeM(el, e) <= targetSizeM * (1.0 + 1e-6)) continue;
        request.regions.push_back({el.centroid[e], farthestCornerM(el, e), targetSizeM});
    }
    return request;
}

}  // namespace hemibake
