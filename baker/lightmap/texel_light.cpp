#include "baker/lightmap/texel_light.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "baker/lightmap/element_interpolation.h"
#include "baker/lightmap/lightmap_baker.h"
#include "baker/util/colour.h"
#include "baker/util/stopwatch.h"
#include "mesh/triangle_sampling.h"

namespace hemibake {

namespace {

// An element's share may differ from the texels' mean over it by this factor before the element stays flat: beyond
// it the texels do not describe the element (it lies in a shadow the texel centres miss, or off its chart).
constexpr double kMaxNormalisation = 2.0;

// Bilinear lookup as the GPU does it (texel centres at (i + ½)/S, clamped at the image's edge).
glm::dvec3 bilinear(const std::vector<glm::vec3>& image, int size, glm::dvec2 texelCoord) {
    const double x = std::clamp(texelCoord.x - 0.5, 0.0, double(size - 1));
    const double y = std::clamp(texelCoord.y - 0.5, 0.0, double(size - 1));
    const int x0 = std::min(int(x), size - 1), y0 = std::min(int(y), size - 1);
    const int x1 = std::min(x0 + 1, size - 1), y1 = std::min(y0 + 1, size - 1);
    const double fx = x - x0, fy = y - y0;
    auto at = [&](int xi, int yi) { return glm::dvec3(image[std::size_t(yi) * std::size_t(size) + std::size_t(xi)]); };
    return (1.0 - fy) * ((1.0 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1.0 - fx) * at(x0, y1) + fx * at(x1, y1));
}

// Mean of the bilinear image over a UV triangle (texel coordinates), at the centroids of its k² equal sub-triangles,
// and whether one of those points falls on a texel flagged in `grid` (if given).
struct TriangleSamples {
    glm::dvec3 mean{0.0};
    bool coversFlagged = false;
};
TriangleSamples sampleTriangle(const std::vector<glm::vec3>& image, const std::vector<std::uint8_t>* grid, int size,
                               const glm::dvec2 t[3]) {
    const double areaTexels = 0.5 * std::abs((t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y));
    const int k = std::clamp(int(std::ceil(2.0 * std::sqrt(areaTexels))), 2, 48);
    TriangleSamples s;
    forEachSubTriangleCentroid(k, [&](double wa, double wb) {
        const glm::dvec2 q = wa * t[0] + wb * t[1] + (1.0 - wa - wb) * t[2];
        s.mean += bilinear(image, size, q);
        if (grid && !s.coversFlagged) {
            const int x = std::clamp(int(std::floor(q.x)), 0, size - 1), y = std::clamp(int(std::floor(q.y)), 0, size - 1);
            s.coversFlagged = (*grid)[std::size_t(y) * std::size_t(size) + std::size_t(x)] != 0;
        }
    });
    s.mean /= double(k * k);
    return s;
}

}  // namespace

std::shared_ptr<TexelLight> makeTexelLight(const Scene& scene, const PatchMesh& mesh, const UvAtlas& atlas,
                                           const std::vector<AtlasTexels>& texels,
                                           const std::vector<std::vector<glm::dvec3>>& texelOverPi,
                                           const std::vector<glm::dvec3>& elementOverPi,
                                           std::vector<glm::vec3>& gatherRadiance, TexelLightStats& stats,
                                           const std::vector<std::vector<std::uint8_t>>* unscaledTexels) {
    const Stopwatch clock;
    auto light = std::make_shared<TexelLight>();
    for (const AtlasTexels& t : texels) light->atlasSize = std::max(light->atlasSize, t.size);
    const int size = light->atlasSize;
    const auto pixels = std::size_t(size) * std::size_t(size);
    light->layers.resize(texels.size());
    tbb::parallel_for(std::size_t(0), texels.size(), [&](std::size_t a) {
        // Padding around the charts is filled, so bilinear lookups at a chart's edge do not blend in black.
        const AtlasTexels& t = texels[a];
        LightmapImage layer;
        layer.resize(size);
        for (std::size_t i = 0; i < t.count(); ++i) {
            const std::size_t px = layer.index(t.x[i], t.y[i]);
            layer.irradianceOverPi[px] = glm::vec3(texelOverPi[a][i]);
            layer.state[px] = TexelState::Covered;
        }
        dilate(layer, 3);
        light->layers[a] = std::move(layer.irradianceOverPi);
    });

    // The flagged texels on each layer's grid.
    std::vector<std::vector<std::uint8_t>> unscaledGrid;
    if (unscaledTexels) {
        unscaledGrid.assign(texels.size(), std::vector<std::uint8_t>(pixels, 0));
        for (std::size_t a = 0; a < texels.size(); ++a)
            for (std::size_t i = 0; i < texels[a].count(); ++i)
                if ((*unscaledTexels)[a][i]) unscaledGrid[a][std::size_t(texels[a].y[i]) * std::size_t(size) + texels[a].x[i]] = 1;
    }

    // Unwrapped triangles by (instance, source face): an element lies in one of its source face's triangles.
    std::vector<std::vector<std::vector<std::uint32_t>>> trianglesOfFace(scene.instances.size());
    for (std::size_t inst = 0; inst < scene.instances.size() && inst < atlas.instances.size(); ++inst) {
        const UnwrappedInstance& ui = atlas.instances[inst];
        const SurfaceMesh& m = scene.instances[inst].mesh;
        auto& byFace = trianglesOfFace[inst];
        for (std::size_t tri = 0; tri < ui.triangles.size(); ++tri) {
            const int source = m.sourceFace(SurfaceMesh::FaceHandle(ui.faceSource[tri]));
            if (source < 0) continue;
            if (std::size_t(source) >= byFace.size()) byFace.resize(std::size_t(source) + 1);
            byFace[std::size_t(source)].push_back(std::uint32_t(tri));
        }
    }

    const ElementArrays& el = mesh.elements;
    light->cornerUvLayer.assign(el.size(), {glm::vec3(0.0f, 0.0f, -1.0f), glm::vec3(0.0f, 0.0f, -1.0f), glm::vec3(0.0f, 0.0f, -1.0f)});
    light->scale.assign(el.size(), glm::vec3(0.0f));
    std::vector<std::uint8_t> outcome(el.size(), 0);  // 1 mapped; lit but flat: 2 no UV triangle, 3 texels disagree
    tbb::parallel_for(std::size_t(0), el.size(), [&](std::size_t e) {
        const glm::dvec3 targetOverPi = e < elementOverPi.size() ? elementOverPi[e] : glm::dvec3(0.0);
        if (!(channelSum(targetOverPi) > 0.0)) return;  // no such light reaches it: nothing to place
        outcome[e] = 2;
        const std::size_t inst = el.instance[e];
        if (el.backSide[e] || inst >= trianglesOfFace.size() || atlas.instances[inst].atlas < 0) return;
        const auto& byFace = trianglesOfFace[inst];
        if (el.sourceFace[e] >= byFace.size()) return;
        const UnwrappedInstance& ui = atlas.instances[inst];
        const SurfaceMesh& m = scene.instances[inst].mesh;
        // The source face's unwrapped triangle that holds the element's centroid best.
        double bestInside = -std::numeric_limits<double>::infinity();
        glm::dvec3 bestP[3];
        glm::dvec2 bestUv[3];
        for (const std::uint32_t tri : byFace[el.sourceFace[e]]) {
            glm::dvec3 p[3];
            for (int j = 0; j < 3; ++j) {
                const auto& q = m.point(SurfaceMesh::VertexHandle(ui.vertexSource[ui.triangles[tri][std::size_t(j)]]));
                p[j] = {q[0], q[1], q[2]};
            }
            if (!(glm::length(glm::cross(p[1] - p[0], p[2] - p[0])) > 0.0)) continue;  // degenerate: holds nothing
            const glm::dvec3 b = barycentric(p[0], p[1], p[2], el.centroid[e]);
            const double inside = std::min({b.x, b.y, b.z});
            if (inside > bestInside) {
                bestInside = inside;
                for (int j = 0; j < 3; ++j) {
                    bestP[j] = p[j];
                    bestUv[j] = glm::dvec2(ui.uv[ui.triangles[tri][std::size_t(j)]]);
                }
            }
        }
        if (!(bestInside > -1e-3)) return;
        const auto layer = std::size_t(ui.atlas);
        const double atlasTexels = double(texels[layer].size);
        glm::dvec2 texelCoord[3];
        for (int c = 0; c < 3; ++c) {
            const glm::dvec3 b = barycentric(bestP[0], bestP[1], bestP[2], el.vertices[el.triangles[e][std::size_t(c)]]);
            texelCoord[c] = atlasTexels * (b.x * bestUv[0] + b.y * bestUv[1] + b.z * bestUv[2]);
        }
        const TriangleSamples samples =
            sampleTriangle(light->layers[layer], unscaledGrid.empty() ? nullptr : &unscaledGrid[layer], size, texelCoord);
        const glm::dvec3 mean = samples.mean;
        const bool normalise = !samples.coversFlagged;
        const double ratio = channelSum(targetOverPi) / std::max(channelSum(mean), 1e-300);
        outcome[e] = 3;
        if (normalise ? !(ratio <= kMaxNormalisation && ratio >= 1.0 / kMaxNormalisation) : !(channelSum(mean) > 0.0)) return;
        const glm::dvec3 rho(el.reflectance[e]);
        glm::dvec3 scale = rho;
        if (normalise)
            for (int c = 0; c < 3; ++c) scale[c] = mean[c] > 0.0 ? rho[c] * targetOverPi[c] / mean[c] : 0.0;
        for (int c = 0; c < 3; ++c)
            light->cornerUvLayer[e][std::size_t(c)] = glm::vec3(glm::vec2(texelCoord[c] / double(size)), float(layer));
        light->scale[e] = glm::vec3(scale);
        gatherRadiance[e] = glm::vec3(glm::max(glm::dvec3(gatherRadiance[e]) - rho * targetOverPi, glm::dvec3(0.0)));
        outcome[e] = 1;
    });
    for (const std::uint8_t o : outcome) {
        stats.elementsMapped += o == 1;
        stats.elementsNoUv += o == 2;
        stats.elementsDisagree += o == 3;
    }
    stats.seconds = clock.seconds();
    return light;
}

}  // namespace hemibake
