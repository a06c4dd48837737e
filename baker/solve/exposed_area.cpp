#include "baker/solve/exposed_area.h"
#include "mesh/triangle_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "baker/rays/embree_scene.h"
#include "mesh/frame_math.h"

namespace hemibake {

namespace {

// Do all rays of a ring just above the surface meet back faces? Sealed along the surface is what tells a point
// inside a closed cover (a block standing on the floor) from one under a roof open at the sides (a single-sided
// card seen from behind), which the cosine-weighted rays, none lower than ≈ 29° above the surface, cannot.
bool sealedAtTheHorizon(const Scene& scene, const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n,
                        const ExposedAreaSettings& s) {
    glm::dvec3 t, b;
    orthonormalBasis(n, t, b);
    const glm::dvec3 origin = rays.offsetFromSurface(p, n);
    const double sinE = std::sin(s.horizonElevationRad), cosE = std::cos(s.horizonElevationRad);
    thread_local std::vector<glm::dvec3> dirs;
    thread_local std::vector<HitSide> sides;
    dirs.resize(std::size_t(s.horizonRays));
    sides.resize(dirs.size());
    for (int i = 0; i < s.horizonRays; ++i) {
        const double phi = 2.0 * M_PI * (i + 0.5) / s.horizonRays;
        const glm::dvec3 dir = sinE * n + cosE * (std::cos(phi) * t + std::sin(phi) * b);
        dirs[std::size_t(i)] = dir / glm::length(dir);
    }
    rays.intersectSides(origin, dirs, std::numeric_limits<double>::infinity(), EmbreeScene::RayEnds::Lifted, sides);
    return std::all_of(sides.begin(), sides.end(), [&](const HitSide& side) { return isSingleSidedBackface(scene, side); });
}

// The test for one sample point. Both parts stop tracing once decided: an open point typically after a handful
// of rays.
bool covered(const Scene& scene, const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n,
             const ExposedAreaSettings& s) {
    return pointInsideGeometry(scene, rays, p, n, s.coveredBackfaceFraction, s.rayStrata) &&
           sealedAtTheHorizon(scene, rays, p, n, s);
}


void validate(const ExposedAreaSettings& s) {
    if (s.samplesPerSide < 1) throw std::invalid_argument("exposed area: samplesPerSide must be at least 1");
    if (s.screenSamplesPerSide < 0) throw std::invalid_argument("exposed area: screenSamplesPerSide must be >= 0");
    if (s.rayStrata < 1 || s.screenRayStrata < 1)
        throw std::invalid_argument("exposed area: rayStrata and screenRayStrata must be at least 1");
    if (s.horizonRays < 1) throw std::invalid_argument("exposed area: horizonRays must be at least 1");
    if (!(s.horizonElevationRad > 0.0 && s.horizonElevationRad < M_PI / 2.0))
        throw std::invalid_argument("exposed area: horizonElevationRad must be in (0, pi/2)");
    if (!(s.coveredBackfaceFraction >= 0.0 && s.coveredBackfaceFraction < 1.0))
        throw std::invalid_argument("exposed area: coveredBackfaceFraction must be in [0, 1)");
    if (!(s.minFraction > 0.0 && s.minFraction <= 1.0))
        throw std::invalid_argument("exposed area: minFraction must be in (0, 1]");
}

}  // namespace

ElementExposure measureExposure(const Scene& scene, const EmbreeScene& rays, const PatchMesh& mesh,
                                const ExposedAreaSettings& settings) {
    validate(settings);
    const ElementArrays& el = mesh.elements;
    ElementExposure out;
    out.fraction.assign(el.size(), 1.0);
    out.centroid = el.centroid;
    const int k = settings.samplesPerSide, screen = settings.screenSamplesPerSide;
    auto normalOf = [&](std::size_t e) { return glm::normalize(glm::dvec3(el.normal[e])); };
    auto degenerate = [&](std::size_t e) { return !(glm::dot(glm::dvec3(el.normal[e]), glm::dvec3(el.normal[e])) > 0.5); };

    // Screening, then its one-ring: elements sharing a vertex with a flagged one are sampled too, since the
    // neighbour of a covered element may hold a covered sliver too thin for any screening point. A covered
    // point shows back faces in nearly every direction, so a few rays per screening point find it.
    std::vector<std::uint8_t> sample(el.size(), 1);
    if (screen > 0 && screen < k) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, el.size(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t e = r.begin(); e != r.end(); ++e) {
                bool anyBackface = false;
                if (!degenerate(e))
                    forEachSubTriangleCentroid(screen, [&](double wa, double wb) {
                        anyBackface = anyBackface || pointInsideGeometry(scene, rays, pointOnElement(el, e, wa, wb), normalOf(e), 0.0,
                                                                         settings.screenRayStrata);
                    });
                sample[e] = anyBackface;
            }
        });
        std::vector<std::uint8_t> nearFlagged(el.vertices.size(), 0);
        for (std::size_t e = 0; e < el.size(); ++e)
            if (sample[e])
                for (std::uint32_t v : el.triangles[e]) nearFlagged[v] = 1;
        for (std::size_t e = 0; e < el.size(); ++e)
            for (std::uint32_t v : el.triangles[e]) sample[e] = sample[e] || nearFlagged[v];
    }

    const std::size_t samples = std::size_t(k) * std::size_t(k);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, el.size(), 4), [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<glm::dvec3> exposed;
        exposed.reserve(samples);
        for (std::size_t e = r.begin(); e != r.end(); ++e) {
            if (!sample[e] || degenerate(e)) continue;
            const glm::dvec3 n = normalOf(e);
            exposed.clear();
            glm::dvec3 sum(0.0);
            forEachSubTriangleCentroid(k, [&](double wa, double wb) {
                const glm::dvec3 p = pointOnElement(el, e, wa, wb);
                if (covered(scene, rays, p, n, settings)) return;
                exposed.push_back(p);
                sum += p;
            });
            if (exposed.size() == samples) continue;  // all open: exactly 1, centroid unchanged
            out.fraction[e] = double(exposed.size()) / double(samples);
            if (exposed.empty()) continue;  // nothing exposed: the triangle's centroid is as good as any point
            // The exposed part's centroid, moved to the nearest exposed point: an L-shaped exposed part (a block's
            // corner over the element) can have its centroid under the block.
            const glm::dvec3 mean = sum / double(exposed.size());
            double best = std::numeric_limits<double>::infinity();
            for (const glm::dvec3& p : exposed) {
                const double d2 = glm::dot(p - mean, p - mean);
                if (d2 < best) best = d2, out.centroid[e] = p;
            }
        }
    });
    return out;
}

ExposedAreaReport applyExposedAreas(const Scene& scene, const EmbreeScene& rays, PatchMesh& mesh,
                                    const ExposedAreaSettings& settings) {
    const ElementExposure exposure = measureExposure(scene, rays, mesh, settings);
    ElementArrays& el = mesh.elements;
    ExposedAreaReport report;
    std::vector<std::uint8_t> patchChanged(mesh.patches.size(), 0);
    for (std::size_t e = 0; e < el.size(); ++e) {
        const double fraction = exposure.fraction[e];
        if (fraction >= 1.0) continue;
        const double full = triangleArea(el, e);
        const double area = std::max(fraction, settings.minFraction) * full;
        report.areaRemovedM2 += el.areaM2[e] - area;
        el.areaM2[e] = area;
        el.centroid[e] = exposure.centroid[e];
        ++(fraction > 0.0 ? report.elementsTrimmed : report.elementsCovered);
        patchChanged[el.patch[e]] = 1;
    }
    // Patch sums as mesh/subdivision.cpp forms them, over the exposed areas.
    for (std::size_t p = 0; p < mesh.patches.size(); ++p)
        if (patchChanged[p]) recomputePatchSums(mesh, p);
    return report;
}

}  // namespace hemibake
