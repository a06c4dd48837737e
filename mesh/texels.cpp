#include "mesh/texels.h"

#include "mesh/frame_math.h"
#include "mesh/islands.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hemibake {

namespace {


// Closest point of triangle abc to p: barycentric weights and squared distance (0 inside).
void closestPoint(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& p, glm::dvec3& bary,
                  double& dist2) {
    const double area2 = cross2(b - a, c - a);
    if (std::abs(area2) > 0.0) {
        const double w0 = cross2(b - p, c - p) / area2;
        const double w1 = cross2(c - p, a - p) / area2;
        const double w2 = 1.0 - w0 - w1;
        if (w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0) {
            bary = {w0, w1, w2};
            dist2 = 0.0;
            return;
        }
    }
    dist2 = std::numeric_limits<double>::infinity();
    const glm::dvec2 v[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
        const glm::dvec2 s = v[k], e = v[(k + 1) % 3];
        const glm::dvec2 d = e - s;
        const double len2 = glm::dot(d, d);
        const double t = len2 > 0.0 ? std::clamp(glm::dot(p - s, d) / len2, 0.0, 1.0) : 0.0;
        const glm::dvec2 q = s + t * d;
        const double d2 = glm::dot(p - q, p - q);
        if (d2 < dist2) {
            dist2 = d2;
            bary = glm::dvec3(0.0);
            bary[k] = 1.0 - t;
            bary[(k + 1) % 3] = t;
        }
    }
}

struct Sample {
    std::uint64_t texel;  // y * size + x
    double dist2;
    std::int32_t instance;
    std::uint32_t triangle;  // unwrapped triangle of that instance
    glm::dvec3 bary;
};

}  // namespace

std::vector<AtlasTexels> computeTexels(const Scene& scene, const UvAtlas& atlas, const TexelSettings& settings) {
    std::vector<AtlasTexels> out(atlas.atlases.size());
    std::vector<std::vector<std::uint32_t>> chartsOfAtlas(atlas.atlases.size());
    for (std::size_t c = 0; c < atlas.charts.size(); ++c)
        chartsOfAtlas[std::size_t(atlas.charts[c].atlas)].push_back(std::uint32_t(c));

    // Per island: copies of a room a kilometre apart keep the room's offset (mesh/islands.h).
    const SceneIslands islands = SceneIslands::ofScene(scene);
    std::vector<double> offsetOfIsland(std::max<std::size_t>(islands.size(), 1));
    for (std::size_t k = 0; k < islands.size(); ++k)  // a relative offset of 0 asks for none at all
        offsetOfIsland[k] = settings.normalOffsetRelative > 0.0
                                ? islands.lengthM(k, settings.normalOffsetRelative, settings.normalOffsetFloatSteps)
                                : 0.0;
    std::vector<Sample> samples;
    std::vector<std::int32_t> local;
    for (std::size_t a = 0; a < atlas.atlases.size(); ++a) {
        const int S = atlas.atlases[a].size;
        samples.clear();
        samples.reserve(std::size_t(atlas.atlases[a].coveredTexels));
        for (std::uint32_t c : chartsOfAtlas[a]) {
            const AtlasChart& ac = atlas.charts[c];
            const UnwrappedInstance& ui = atlas.instances[std::size_t(ac.instance)];
            // Chart-local grid over the chart's texel bounding box: index into samples, or -1.
            glm::dvec2 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
            for (std::uint32_t t = ac.firstTriangle; t < ac.firstTriangle + ac.triangleCount; ++t)
                for (std::uint32_t v : ui.triangles[t]) {
                    const glm::dvec2 p = glm::dvec2(ui.uv[v]) * double(S);
                    lo = glm::min(lo, p);
                    hi = glm::max(hi, p);
                }
            if (!(lo.x <= hi.x)) continue;
            const int gx0 = std::max(0, int(std::floor(lo.x)) - 1), gy0 = std::max(0, int(std::floor(lo.y)) - 1);
            const int gx1 = std::min(S, int(std::ceil(hi.x)) + 1), gy1 = std::min(S, int(std::ceil(hi.y)) + 1);
            const int gw = gx1 - gx0, gh = gy1 - gy0;
            if (gw <= 0 || gh <= 0) continue;
            local.assign(std::size_t(gw) * std::size_t(gh), -1);
            for (std::uint32_t t = ac.firstTriangle; t < ac.firstTriangle + ac.triangleCount; ++t) {
                const auto& tri = ui.triangles[t];
                const glm::dvec2 p0 = glm::dvec2(ui.uv[tri[0]]) * double(S);
                const glm::dvec2 p1 = glm::dvec2(ui.uv[tri[1]]) * double(S);
                const glm::dvec2 p2 = glm::dvec2(ui.uv[tri[2]]) * double(S);
                forEachTouchedTexel(p0, p1, p2, settings.coverageShrinkTexels, [&](long x, long y) {
                    if (x < gx0 || y < gy0 || x >= gx1 || y >= gy1) return;
                    glm::dvec3 bary;
                    double d2;
                    closestPoint(p0, p1, p2, glm::dvec2(double(x) + 0.5, double(y) + 0.5), bary, d2);
                    auto& slot = local[std::size_t(y - gy0) * std::size_t(gw) + std::size_t(x - gx0)];
                    if (slot < 0) {
                        slot = std::int32_t(samples.size());
                        samples.push_back({std::uint64_t(y) * std::uint64_t(S) + std::uint64_t(x), d2, ac.instance, t, bary});
                    } else if (d2 < samples[std::size_t(slot)].dist2) {
                        samples[std::size_t(slot)] = {std::uint64_t(y) * std::uint64_t(S) + std::uint64_t(x), d2, ac.instance, t, bary};
                    }
                });
            }
        }
        // Row-major order; a texel claimed by two charts (only possible with overlapping existing UVs) keeps
        // the closer sample.
        std::stable_sort(samples.begin(), samples.end(), [](const Sample& l, const Sample& r) {
            return l.texel < r.texel || (l.texel == r.texel && l.dist2 < r.dist2);
        });
        AtlasTexels& at = out[a];
        at.atlas = std::int32_t(a);
        at.size = S;
        const std::size_t n = samples.size();
        at.x.reserve(n);
        at.y.reserve(n);
        at.position.reserve(n);
        at.normal.reserve(n);
        at.instance.reserve(n);
        at.face.reserve(n);
        at.barycentric.reserve(n);
        at.centreInside.reserve(n);
        for (std::size_t k = 0; k < n; ++k) {
            const Sample& s = samples[k];
            if (k > 0 && samples[k - 1].texel == s.texel) continue;
            const UnwrappedInstance& ui = atlas.instances[std::size_t(s.instance)];
            const SurfaceMesh& mesh = scene.instances[std::size_t(s.instance)].mesh;
            const auto& tri = ui.triangles[s.triangle];
            glm::dvec3 P[3];
            for (int j = 0; j < 3; ++j) {
                const auto& p = mesh.point(SurfaceMesh::VertexHandle(ui.vertexSource[tri[std::size_t(j)]]));
                P[j] = {p[0], p[1], p[2]};
            }
            glm::dvec3 bary = s.bary;
            if (s.dist2 > 0.0 && settings.borderInsetTexels > 0.0) {
                // Step from the chart's edge toward the triangle's centroid: an edge is often a concave corner
                // (wall meets floor), where any sample point — hemicube eye or ray origin — sits at the singular
                // contact line. The step stays on the segment to the centroid, so inside the triangle.
                glm::dvec2 uv[3];
                for (int j = 0; j < 3; ++j) uv[j] = glm::dvec2(ui.uv[tri[std::size_t(j)]]) * double(S);
                const glm::dvec2 q = bary.x * uv[0] + bary.y * uv[1] + bary.z * uv[2];
                const glm::dvec2 c = (uv[0] + uv[1] + uv[2]) / 3.0;
                const double d = glm::length(c - q);
                if (d > 0.0) bary += std::min(0.5, settings.borderInsetTexels / d) * (glm::dvec3(1.0 / 3.0) - bary);
            }
            const glm::dvec3 cr = glm::cross(P[1] - P[0], P[2] - P[0]);
            const double len = glm::length(cr);
            const glm::dvec3 nrm = len > 0.0 ? cr / len : glm::dvec3(0.0);
            const glm::dvec3 pos = bary.x * P[0] + bary.y * P[1] + bary.z * P[2];

            at.x.push_back(std::uint16_t(s.texel % std::uint64_t(S)));
            at.y.push_back(std::uint16_t(s.texel / std::uint64_t(S)));
            at.position.push_back(pos + nrm * offsetOfIsland[islands.islandOfPart(std::size_t(s.instance))]);
            at.normal.push_back(glm::vec3(nrm));
            at.instance.push_back(s.instance);
            at.face.push_back(ui.faceSource[s.triangle]);
            at.barycentric.push_back(glm::vec3(bary));
            at.centreInside.push_back(s.dist2 == 0.0 ? 1 : 0);
        }
    }
    return out;
}

}  // namespace hemibake
