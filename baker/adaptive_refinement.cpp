#include "baker/adaptive_refinement.h"

#include <algorithm>
#include <unordered_map>

#include "baker/embree_scene.h"
#include "baker/exposed_area.h"
#include "raster/hemicube_pool.h"

namespace hemibake {

RadiosityBake::RadiosityBake() = default;
RadiosityBake::~RadiosityBake() = default;

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
        double longest = 0.0, radius = 0.0;
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3& p = el.vertices[el.triangles[e][std::size_t(k)]];
            longest = std::max(longest, glm::length(p - el.vertices[el.triangles[e][std::size_t((k + 1) % 3)]]));
            radius = std::max(radius, glm::length(p - el.centroid[e]));
        }
        if (longest <= targetSizeM * (1.0 + 1e-6)) continue;
        // Slightly inside the element's circumradius: the region covers this element's refined faces, not its
        // neighbours' (whose centroids lie further out).
        request.regions.push_back({el.centroid[e], radius, targetSizeM});
    }
    return request;
}

std::unique_ptr<RadiosityBake> solveWithRefinement(const Scene& scene, const BakeSettings& settings,
                                                   const EmbreeScene& rays, const SolveProgress& progress) {
    auto owned = std::make_unique<RadiosityBake>();
    RadiosityBake& bake = *owned;
    // Elements partly under other geometry keep only their exposed area (baker/exposed_area.h).
    const ExposedAreaSettings exposed;
    bake.mesh = subdivide(scene, settings.subdivision);
    bake.exposedArea = applyExposedAreas(scene, rays, bake.mesh, exposed);
    bake.elementsBeforeRefinement = bake.mesh.elements.size();
    bake.pool = std::make_unique<HemicubePool>(bake.mesh, settings.solver.hemicubeResolution);
    bake.report = solveRadiosity(scene, bake.mesh, settings, *bake.pool, rays, bake.solution, progress);
    // Regions accumulate over levels: each re-subdivision starts from the unrefined mesh.
    RefinementRequest request;
    for (int level = 1; level <= settings.adaptive.levels; ++level) {
        const double target = settings.subdivision.elementSizeM / double(1 << level);
        const RefinementRequest found = findRadiosityDiscontinuities(bake.mesh, bake.solution, settings.adaptive.threshold, target);
        if (found.regions.empty()) break;
        request.regions.insert(request.regions.end(), found.regions.begin(), found.regions.end());
        bake.refinementRegions = request.regions.size();
        bake.pool.reset();
        bake.mesh = subdivide(scene, settings.subdivision, &request);
        bake.exposedArea = applyExposedAreas(scene, rays, bake.mesh, exposed);
        bake.pool = std::make_unique<HemicubePool>(bake.mesh, settings.solver.hemicubeResolution);
        bake.report = solveRadiosity(scene, bake.mesh, settings, *bake.pool, rays, bake.solution, progress);
    }
    return owned;
}

}  // namespace hemibake
