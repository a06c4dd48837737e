#include "baker/lightmap/surface_agreement.h"

#include <cmath>
#include <limits>
#include <map>
#include <numbers>

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
    // Front elements by the input triangle they subdivide.
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> elementsOfFace;
    for (std::size_t e = 0; e < el.areaM2.size(); ++e)
        if (!el.backSide[e]) elementsOfFace[{el.instance[e], el.sourceFace[e]}].push_back(std::uint32_t(e));

    const std::size_t instances = scene.instances.size();
    std::vector<glm::dvec3> elementSum(instances, glm::dvec3(0.0)), texelSum(instances, glm::dvec3(0.0));
    std::vector<std::size_t> count(instances, 0);
    for (std::size_t a = 0; a < texels.size() && a < lightmaps.size(); ++a) {
        const AtlasTexels& t = texels[a];
        const LightmapImage& image = lightmaps[a];
        for (std::size_t i = 0; i < t.x.size(); ++i) {
            // Chart-border texels sample the chart's closest point, not their centre: they would weigh the
            // border twice.
            if (!t.centreInside[i] || t.instance[i] < 0 || std::size_t(t.instance[i]) >= instances) continue;
            if (a < insideGeometry.size() && i < insideGeometry[a].size() && insideGeometry[a][i]) continue;
            const auto sourceFace = std::uint32_t(
                scene.instances[std::size_t(t.instance[i])].mesh.sourceFace(SurfaceMesh::FaceHandle(t.face[i])));
            const auto it = elementsOfFace.find({std::uint32_t(t.instance[i]), sourceFace});
            if (it == elementsOfFace.end()) continue;
            std::uint32_t nearest = it->second.front();
            double best = std::numeric_limits<double>::infinity();
            for (const std::uint32_t e : it->second) {
                const auto& tri = el.triangles[e];
                const double d = squaredDistanceToTriangle(t.position[i], el.vertices[tri[0]], el.vertices[tri[1]], el.vertices[tri[2]]);
                if (d < best) best = d, nearest = e;
            }
            const std::size_t inst = std::size_t(t.instance[i]);
            elementSum[inst] += solution.displayIrradiance(nearest) / std::numbers::pi;
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
