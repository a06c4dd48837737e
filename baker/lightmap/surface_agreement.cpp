#include "baker/lightmap/surface_agreement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "mesh/cell_key.h"

namespace hemibake {

namespace {

// Squared distance from p to triangle abc (Ericson, Real-Time Collision Detection §5.1.5), for picking the
// element a texel sample lies on: the sample is nudged off the surface, so "contains" needs a distance.
double squaredDistanceToTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return glm::dot(ap, ap);
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return glm::dot(bp, bp);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        const glm::dvec3 q = a + ab * (d1 / (d1 - d3)) - p;
        return glm::dot(q, q);
    }
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return glm::dot(cp, cp);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        const glm::dvec3 q = a + ac * (d2 / (d2 - d6)) - p;
        return glm::dot(q, q);
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        const glm::dvec3 q = b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))) - p;
        return glm::dot(q, q);
    }
    const double denom = 1.0 / (va + vb + vc);
    const glm::dvec3 q = a + ab * (vb * denom) + ac * (vc * denom) - p;
    return glm::dot(q, q);
}

}  // namespace

double SurfaceAgreement::relativeDifference() const {
    const double e = elementMean.x + elementMean.y + elementMean.z;
    const double l = lightmapMean.x + lightmapMean.y + lightmapMean.z;
    if (!(e > 0.0)) return l > 0.0 ? 1.0 : 0.0;
    return std::abs(l - e) / e;
}

std::vector<SurfaceAgreement> compareSurfaceMeans(const Scene& scene, const PatchMesh& mesh, const RadiositySolution& solution,
                                                  const std::vector<AtlasTexels>& texels,
                                                  const std::vector<LightmapImage>& lightmaps,
                                                  const std::vector<std::vector<std::uint8_t>>& insideGeometry) {
    const ElementArrays& el = mesh.elements;
    // Front elements in a uniform grid of their centroids, cells as large as the longest element edge, keyed by
    // cell and input triangle: the element a texel lies on has its centroid in the texel's cell or a neighbour.
    // (Scanning every element of the texel's input triangle took 30 s of the 100k level's bake, serially: a floor
    // triangle holds thousands.)
    double cellM = 0.0;
    for (std::size_t e = 0; e < el.size(); ++e) {
        const auto& tri = el.triangles[e];
        const glm::dvec3 a = el.vertices[tri[0]], b = el.vertices[tri[1]], c = el.vertices[tri[2]];
        cellM = std::max({cellM, glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    }
    cellM = cellM > 0.0 ? 1.001 * cellM : 1.0;
    const glm::dvec3 origin = mesh.origin;
    auto cellOf = [&](const glm::dvec3& p) { return glm::i64vec3(glm::floor((p - origin) / cellM)); };
    auto keyOf = [](std::uint32_t instance, std::uint32_t face, const glm::i64vec3& cell) {
        return cellKey(cell.x, cell.y, cell.z) ^ ((std::uint64_t(instance) << 32 | face) * 0xD6E8FEB86659FD93ull);
    };
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid;
    for (std::size_t e = 0; e < el.size(); ++e)
        if (!el.backSide[e]) grid[keyOf(el.instance[e], el.sourceFace[e], cellOf(el.centroid[e]))].push_back(std::uint32_t(e));

    // The element nearest to texel i of atlas t among those of its input triangle; -1 if it has none. The lowest
    // index wins a tie (a texel on an edge), whatever order the cells list them in. Thread-safe.
    auto nearestElement = [&](const AtlasTexels& t, std::size_t i) -> std::int64_t {
        const auto instance = std::uint32_t(t.instance[i]);
        const auto sourceFace = std::uint32_t(scene.instances[instance].mesh.sourceFace(SurfaceMesh::FaceHandle(t.face[i])));
        const glm::i64vec3 centre = cellOf(t.position[i]);
        std::int64_t nearest = -1;
        double best = std::numeric_limits<double>::infinity();
        for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
                for (std::int64_t dz = -1; dz <= 1; ++dz) {
                    const auto it = grid.find(keyOf(instance, sourceFace, centre + glm::i64vec3(dx, dy, dz)));
                    if (it == grid.end()) continue;
                    for (const std::uint32_t e : it->second) {
                        if (el.instance[e] != instance || el.sourceFace[e] != sourceFace) continue;  // a key collision
                        const auto& tri = el.triangles[e];
                        const double d = squaredDistanceToTriangle(t.position[i], el.vertices[tri[0]], el.vertices[tri[1]],
                                                                   el.vertices[tri[2]]);
                        if (d < best || (d == best && std::int64_t(e) < nearest)) best = d, nearest = e;
                    }
                }
        return nearest;
    };

    const std::size_t instances = scene.instances.size();
    std::vector<glm::dvec3> elementSum(instances, glm::dvec3(0.0)), texelSum(instances, glm::dvec3(0.0));
    std::vector<std::size_t> count(instances, 0);
    std::vector<std::int64_t> nearest;
    for (std::size_t a = 0; a < texels.size() && a < lightmaps.size(); ++a) {
        const AtlasTexels& t = texels[a];
        const LightmapImage& image = lightmaps[a];
        // Chart-border texels sample the chart's closest point, not their centre: they would weigh the border twice.
        auto compared = [&](std::size_t i) {
            return t.centreInside[i] && t.instance[i] >= 0 && std::size_t(t.instance[i]) < instances &&
                   !(a < insideGeometry.size() && i < insideGeometry[a].size() && insideGeometry[a][i]);
        };
        nearest.assign(t.x.size(), -1);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, t.x.size()), [&](const tbb::blocked_range<std::size_t>& range) {
            for (std::size_t i = range.begin(); i != range.end(); ++i)
                if (compared(i)) nearest[i] = nearestElement(t, i);
        });
        // Summed in texel order, as before the search ran in parallel: the report does not depend on the threads.
        for (std::size_t i = 0; i < t.x.size(); ++i) {
            if (nearest[i] < 0) continue;
            const std::size_t inst = std::size_t(t.instance[i]);
            elementSum[inst] += solution.displayIrradiance(std::size_t(nearest[i])) / std::numbers::pi;
            texelSum[inst] += glm::dvec3(image.irradianceOverPi[image.index(t.x[i], t.y[i])]);
            ++count[inst];
        }
    }
    std::vector<SurfaceAgreement> result;
    for (std::size_t i = 0; i < instances; ++i) {
        if (count[i] == 0) continue;
        SurfaceAgreement s;
        s.instance = int(i);
        s.nodeName = scene.instances[i].source.nodeName;
        s.elementMean = elementSum[i] / double(count[i]);
        s.lightmapMean = texelSum[i] / double(count[i]);
        s.texels = count[i];
        result.push_back(s);
    }
    return result;
}

}  // namespace hemibake
