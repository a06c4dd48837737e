#include "baker/solve/room_scale.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <tbb/parallel_for.h>

#include "mesh/frame_math.h"
#include "mesh/triangle_sampling.h"

namespace hemibake {

namespace {

struct FreePath {
    double meanM = 0.0;  // over the rays that hit a front face
    bool measured = false;
};

// Cosine-weighted stratified rays from the element's centroid (fixed strata centres: deterministic), traced as
// packets of 16 from the one origin.
FreePath measureFreePath(const EmbreeScene& rays, const glm::dvec3& centroid, const glm::dvec3& n, int raysPerElement) {
    const int side = std::max(1, int(std::ceil(std::sqrt(double(raysPerElement)))));
    const glm::dvec3 origin = rays.offsetFromSurface(centroid, n);
    glm::dvec3 t, b;
    orthonormalBasis(n, t, b);
    thread_local std::vector<glm::dvec3> dirs;
    thread_local std::vector<HitSide> hits;
    dirs.clear();
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j) dirs.push_back(cosineDirection(t, b, n, (i + 0.5) / side, (j + 0.5) / side));
    hits.resize(dirs.size());
    rays.intersectSides(origin, dirs, std::numeric_limits<double>::infinity(), EmbreeScene::RayEnds::Lifted, hits);
    double sum = 0.0;
    int front = 0, back = 0, escaped = 0;
    for (const HitSide& hit : hits) {
        if (!hit.hit) ++escaped;
        else if (hit.frontFacing) sum += hit.distanceM, ++front;
        else ++back;
    }
    FreePath path;
    const int total = side * side;
    // Open to the sky or inside geometry: the room has no size to follow.
    if (2 * escaped >= total || 2 * back >= total || front == 0) return path;
    path.meanM = sum / front;
    path.measured = true;
    return path;
}

}  // namespace

RefinementRequest findRoomScaleRegions(const Scene& scene, const EmbreeScene& rays, const SolveSettings& settings,
                                       RoomScaleReport* report) {
    const RoomScaleSettings& s = settings.roomScale;
    if (!(s.roomFraction >= 0.0) || s.raysPerElement < 0 || !(s.minSizeFraction >= 0.0))
        throw std::invalid_argument("room scale: roomFraction, raysPerElement and minSizeFraction must not be negative");
    RefinementRequest request;
    if (report) *report = {};
    if (s.roomFraction == 0.0 || s.raysPerElement == 0) return request;
    const PatchMesh mesh = subdivide(scene, settings.subdivision);
    const ElementArrays& el = mesh.elements;
    std::vector<FreePath> paths(el.size());
    tbb::parallel_for(std::size_t(0), el.size(), [&](std::size_t e) {
        if (el.emittedRadiance[e] != glm::vec3(0.0f)) return;  // emitters keep the emitter patch size
        paths[e] = measureFreePath(rays, el.centroid[e], glm::dvec3(el.normal[e]), s.raysPerElement);
    });
    const double floorM = settings.subdivision.elementSizeM * s.minSizeFraction;
    std::vector<std::pair<double, double>> measured;  // (free path, area) for the report
    for (std::size_t e = 0; e < el.size(); ++e) {
        if (!paths[e].measured) continue;
        measured.emplace_back(paths[e].meanM, el.areaM2[e]);
        const double sizeM = std::max(s.roomFraction * paths[e].meanM, floorM);
        if (!(sizeM < longestEdgeM(el, e) * (1.0 - 1e-6))) continue;
        request.regions.push_back({el.centroid[e], farthestCornerM(el, e), sizeM});
    }
    if (report) {
        report->regions = request.regions.size();
        for (const auto& r : request.regions)
            report->smallestSizeM = report->smallestSizeM == 0.0 ? r.sizeM : std::min(report->smallestSizeM, r.sizeM);
        std::sort(measured.begin(), measured.end());
        double total = 0.0, acc = 0.0;
        for (const auto& m : measured) total += m.second;
        for (const auto& m : measured)
            if ((acc += m.second) >= 0.5 * total) {
                report->medianFreePathM = m.first;
                break;
            }
    }
    return request;
}

}  // namespace hemibake
