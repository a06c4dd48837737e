#include "baker/solve/separate_sides.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <unordered_set>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "baker/rays/embree_scene.h"
#include "baker/rays/inside_geometry.h"
#include "baker/util/stopwatch.h"
#include "mesh/triangle_sampling.h"
#include "mesh/union_find.h"

namespace hemibake {

namespace {

// Lift off the face: relative to the element, never below what float error in the ray tracer can undo.
double liftM(const EmbreeScene& rays, double edgeM, const SideSeparationSettings& s) {
    return std::max(s.liftFraction * edgeM, 4.0 * rays.rayEpsilonM());
}

// A point lifted off a face lies inside a solid when most of its cosine-weighted rays (4 × 4 strata) meet back
// faces first. One ray along the normal is not enough where solids overlap: from inside a wall that reaches into
// the ceiling slab, the ray up meets the slab's front face.
bool buried(const EmbreeScene& rays, const glm::dvec3& lifted, const glm::dvec3& n) {
    return pointInsideGeometry(rays.scene(), rays, lifted, n, 0.5, 4);
}

// The same triangle on the same side of the same instance, between two subdivisions (exact: bisection computes
// midpoints identically each time).
std::uint64_t triangleKey(const ElementArrays& el, std::size_t e) {
    std::uint64_t h = 0xcbf29ce484222325ull ^ (std::uint64_t(el.instance[e]) << 1) ^ el.backSide[e];
    for (std::uint32_t v : el.triangles[e]) {
        const glm::dvec3& p = el.vertices[v];
        for (int c = 0; c < 3; ++c) {
            std::uint64_t bits;
            std::memcpy(&bits, &p[c], sizeof bits);
            h = (h ^ bits) * 0x100000001b3ull;
            h ^= h >> 29;
        }
    }
    return h;
}

}  // namespace

bool elementStraddles(const EmbreeScene& rays, const PatchMesh& mesh, std::size_t e, const SideSeparationSettings& s) {
    const ElementArrays& el = mesh.elements;
    const glm::dvec3 normal(el.normal[e]);
    if (!(glm::dot(normal, normal) > 0.5)) return false;  // degenerate
    const glm::dvec3 n = glm::normalize(normal);
    const double lift = liftM(rays, longestEdgeM(el, e), s);
    std::vector<glm::dvec3> points;
    points.reserve(std::size_t(s.samplesPerSide) * std::size_t(s.samplesPerSide));
    forEachSubTriangleCentroid(s.samplesPerSide, [&](double wa, double wb) {
        const glm::dvec3 q = pointOnElement(el, e, wa, wb) + lift * n;
        if (!buried(rays, q, n)) points.push_back(q);
    });
    if (points.size() < 2) return false;
    UnionFind groups(points.size());
    std::size_t count = points.size();
    // All pairs, so that an obstacle inside the element (a pillar) is walked around; an open element is done
    // after the first point's row (count reaches 1).
    for (std::uint32_t i = 0; i < points.size() && count > 1; ++i)
        for (std::uint32_t j = i + 1; j < points.size() && count > 1; ++j)
            if (groups.find(i) != groups.find(j) && !rays.occluded(points[i], points[j], EmbreeScene::RayEnds::Lifted))
                count -= groups.unite(i, j) ? 1 : 0;
    return count > 1;
}

std::size_t splitPatchesBySide(const EmbreeScene& rays, PatchMesh& mesh, const SideSeparationSettings& settings,
                               std::size_t* patchesSplit) {
    ElementArrays& el = mesh.elements;
    PatchArrays& pa = mesh.patches;
    // Elements around each vertex (CSR).
    std::vector<std::uint32_t> start(el.vertices.size() + 1, 0), around;
    for (const auto& tri : el.triangles)
        for (std::uint32_t v : tri) ++start[v + 1];
    for (std::size_t v = 0; v < el.vertices.size(); ++v) start[v + 1] += start[v];
    around.resize(start.back());
    {
        std::vector<std::uint32_t> cursor(start.begin(), start.end() - 1);
        for (std::uint32_t e = 0; e < el.size(); ++e)
            for (std::uint32_t v : el.triangles[e]) around[cursor[v]++] = e;
    }
    // Per element, the group (0, 1, ...) within its patch; groups numbered by their first element.
    std::vector<std::uint32_t> group(el.size(), 0), groupCount(pa.size(), 1);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pa.size(), 8), [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<glm::dvec3> lifted;
        std::vector<std::uint8_t> isBuried;
        for (std::size_t p = r.begin(); p != r.end(); ++p) {
            const std::uint32_t first = pa.firstElement[p], count = pa.elementCount[p];
            if (count < 2) continue;
            lifted.resize(count);
            isBuried.assign(count, 0);
            for (std::uint32_t k = 0; k < count; ++k) {
                const std::uint32_t e = first + k;
                const glm::dvec3 normal(el.normal[e]);
                if (!(glm::dot(normal, normal) > 0.5)) {
                    isBuried[k] = 1;
                    continue;
                }
                const glm::dvec3 n = glm::normalize(normal);
                const double lift = liftM(rays, longestEdgeM(el, e), settings);
                lifted[k] = el.centroid[e] + lift * n;
                isBuried[k] = buried(rays, lifted[k], n);
                if (!isBuried[k]) continue;
                // The centroid is under a wall: the element takes the side of its open sample point nearest the
                // centroid (an element at a wall's foot, mostly buried, with its open strip in one room).
                double best = std::numeric_limits<double>::infinity();
                forEachSubTriangleCentroid(settings.samplesPerSide, [&](double wa, double wb) {
                    const glm::dvec3 q = pointOnElement(el, e, wa, wb);
                    const double d2 = glm::dot(q - el.centroid[e], q - el.centroid[e]);
                    if (d2 >= best || buried(rays, q + lift * n, n)) return;
                    best = d2;
                    lifted[k] = q + lift * n;
                    isBuried[k] = 0;
                });
            }
            UnionFind groups(count);
            for (std::uint32_t k = 0; k < count; ++k) {
                if (isBuried[k]) continue;
                for (std::uint32_t v : el.triangles[first + k])
                    for (std::uint32_t i = start[v]; i < start[v + 1]; ++i) {
                        const std::uint32_t other = around[i];
                        if (other <= first + k || other >= first + count) continue;  // each pair once, this patch only
                        const std::uint32_t j = other - first;
                        if (isBuried[j] || groups.find(k) == groups.find(j)) continue;
                        if (!rays.occluded(lifted[k], lifted[j], EmbreeScene::RayEnds::Lifted)) groups.unite(k, j);
                    }
            }
            // Group sizes by area; buried elements join the largest.
            std::vector<double> area(count, 0.0);
            for (std::uint32_t k = 0; k < count; ++k)
                if (!isBuried[k]) area[groups.find(k)] += el.areaM2[first + k];
            const std::uint32_t largest = std::uint32_t(std::max_element(area.begin(), area.end()) - area.begin());
            std::vector<std::uint32_t> number(count, ~0u);
            std::uint32_t groupsHere = 0;
            for (std::uint32_t k = 0; k < count; ++k) {
                const std::uint32_t root = isBuried[k] ? largest : groups.find(k);
                if (number[root] == ~0u) number[root] = groupsHere++;
                group[first + k] = number[root];
            }
            groupCount[p] = groupsHere;
        }
    });
    std::size_t added = 0, split = 0;
    for (std::size_t p = 0; p < pa.size(); ++p)
        if (groupCount[p] > 1) added += groupCount[p] - 1, ++split;
    if (patchesSplit) *patchesSplit = split;
    if (added == 0) return 0;

    // Reorder each patch's run by group (stable), then give each group its own patch.
    std::vector<std::uint32_t> order(el.size());
    std::iota(order.begin(), order.end(), std::uint32_t(0));
    for (std::size_t p = 0; p < pa.size(); ++p) {
        if (groupCount[p] < 2) continue;
        const auto begin = order.begin() + pa.firstElement[p];
        std::stable_sort(begin, begin + pa.elementCount[p], [&](std::uint32_t a, std::uint32_t b) { return group[a] < group[b]; });
    }
    auto permute = [&](auto& v) {
        auto copy = v;
        for (std::size_t i = 0; i < order.size(); ++i) v[i] = copy[order[i]];
    };
    permute(el.triangles);
    permute(el.normal);
    permute(el.centroid);
    permute(el.areaM2);
    permute(el.reflectance);
    permute(el.emittedRadiance);
    permute(el.instance);
    permute(el.sourceFace);
    permute(el.backSide);
    permute(group);

    PatchArrays out;
    for (std::size_t p = 0; p < pa.size(); ++p) {
        const std::uint32_t first = pa.firstElement[p], end = first + pa.elementCount[p];
        for (std::uint32_t a = first; a < end;) {
            std::uint32_t b = a;
            while (b < end && group[b] == group[a]) ++b;
            const auto index = std::uint32_t(out.firstElement.size());
            for (std::uint32_t e = a; e < b; ++e) el.patch[e] = index;
            out.firstElement.push_back(a);
            out.elementCount.push_back(b - a);
            out.areaM2.push_back(pa.areaM2[p]);
            out.centroid.push_back(pa.centroid[p]);
            out.normal.push_back(pa.normal[p]);
            out.reflectance.push_back(pa.reflectance[p]);
            out.emittedRadiance.push_back(pa.emittedRadiance[p]);
            out.instance.push_back(pa.instance[p]);
            a = b;
        }
    }
    pa = std::move(out);
    for (std::size_t p = 0; p < pa.size(); ++p) recomputePatchSums(mesh, p);
    return added;
}

PatchMesh subdivideApart(const Scene& scene, const EmbreeScene& rays, const SubdivisionSettings& sizes,
                         const RefinementRequest* request, const SideSeparationSettings& settings,
                         SideSeparationReport* report) {
    if (!settings.enabled) return subdivide(scene, sizes, request);
    const Stopwatch clock;
    SideSeparationReport local;
    SideSeparationReport& r = report ? *report : local;
    r = SideSeparationReport{};
    RefinementRequest all = request ? *request : RefinementRequest{};
    PatchMesh mesh = subdivide(scene, sizes, &all);
    const double minEdgeM = sizes.elementSizeM * settings.minEdgeFraction;
    std::unordered_set<std::uint64_t> open;  // triangles already found not to straddle
    for (;;) {
        const ElementArrays& el = mesh.elements;
        std::vector<std::uint8_t> straddles(el.size(), 0);
        std::vector<std::uint64_t> keys(el.size());
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, el.size(), 16), [&](const tbb::blocked_range<std::size_t>& range) {
            for (std::size_t e = range.begin(); e != range.end(); ++e) {
                keys[e] = triangleKey(el, e);
                if (open.count(keys[e])) continue;
                straddles[e] = elementStraddles(rays, mesh, e, settings);
            }
        });
        std::size_t left = 0;
        RefinementRequest found;
        for (std::size_t e = 0; e < el.size(); ++e) {
            if (!straddles[e]) {
                open.insert(keys[e]);
                continue;
            }
            const double longest = longestEdgeM(el, e);
            if (longest <= minEdgeM * (1.0 + 1e-6)) {
                ++left;
                continue;
            }
            found.regions.push_back({el.centroid[e], farthestCornerM(el, e), std::max(0.5 * longest, minEdgeM)});
        }
        r.straddlingElementsLeft = left;
        if (found.regions.empty()) break;
        all.regions.insert(all.regions.end(), found.regions.begin(), found.regions.end());
        r.regions += found.regions.size();
        ++r.levels;
        mesh = subdivide(scene, sizes, &all);
    }
    r.patchesAdded = splitPatchesBySide(rays, mesh, settings, &r.patchesSplit);
    r.seconds = clock.seconds();
    return mesh;
}

}  // namespace hemibake
