#include "baker/lightmap/lightmap_seams.h"

#include <algorithm>
#include <cmath>
#include <array>
#include <map>

#include "mesh/islands.h"

namespace hemibake {

namespace {

// Faces meeting at less than ~15° count as one smooth surface.
constexpr double kSmoothCos = 0.966;

struct SeamSample {
    int atlas;
    std::size_t texels[2][4];
    float weights[2][4];
};

// The 4 texels and weights of a bilinear lookup at glTF UV (texel centres at (i+0.5)/size), clamped to the atlas.
void bilinear(const LightmapImage& image, glm::vec2 uv, std::size_t (&texels)[4], float (&weights)[4]) {
    const float x = uv.x * float(image.size) - 0.5f, y = uv.y * float(image.size) - 0.5f;
    const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
    const float fx = x - float(x0), fy = y - float(y0);
    auto clampC = [&](int c) { return std::clamp(c, 0, image.size - 1); };
    const int xs[2] = {clampC(x0), clampC(x0 + 1)}, ys[2] = {clampC(y0), clampC(y0 + 1)};
    for (int k = 0; k < 4; ++k) {
        texels[k] = image.index(xs[k & 1], ys[k >> 1]);
        weights[k] = ((k & 1) ? fx : 1.0f - fx) * ((k >> 1) ? fy : 1.0f - fy);
    }
}

glm::vec3 lookup(const LightmapImage& image, const std::size_t (&texels)[4], const float (&weights)[4]) {
    glm::vec3 v(0.0f);
    for (int k = 0; k < 4; ++k) v += weights[k] * image.irradianceOverPi[texels[k]];
    return v;
}

std::vector<SeamSample> findSeamSamples(const Scene& scene, const UvAtlas& atlas, const std::vector<LightmapImage>& images,
                                        std::size_t& seamEdges) {
    std::vector<SeamSample> samples;
    // Relative to the instance's island (mesh/islands.h): an absolute floor would weld distinct vertices of a
    // millimetre-sized scene, and the whole scene's diagonal those of copies of a room a kilometre apart. Islands once,
    // not per instance: their bounds visit every vertex of the scene (a level's 242 instances took 4.3 s here).
    const SceneIslands islands = SceneIslands::ofScene(scene);
    for (std::size_t i = 0; i < atlas.instances.size(); ++i) {
        const UnwrappedInstance& u = atlas.instances[i];
        if (u.atlas < 0) continue;
        const LightmapImage& image = images[std::size_t(u.atlas)];
        // Mesh edge → the UVs of its ends as each unwrapped triangle sees them. Ends are keyed by quantised
        // position, not vertex index: non-indexed glTF gives every triangle its own vertices.
        const SurfaceMesh& mesh = scene.instances[i].mesh;
        const double diagonalM = islands.bounds(islands.islandOfPart(i)).diagonal();
        const double quantum = diagonalM > 0.0 ? 1e-7 * diagonalM : 1e-7;
        std::map<std::array<std::int64_t, 3>, std::int32_t> positionId;
        auto idOf = [&](std::int32_t v) {
            const auto p = mesh.point(SurfaceMesh::VertexHandle(v));
            const std::array<std::int64_t, 3> key{std::llround(p[0] / quantum), std::llround(p[1] / quantum),
                                                  std::llround(p[2] / quantum)};
            return positionId.emplace(key, std::int32_t(positionId.size())).first->second;
        };
        struct Side {
            glm::vec2 a, b;
            OpenMesh::Vec3d normal;
        };
        std::map<std::pair<std::int32_t, std::int32_t>, std::vector<Side>> edges;
        for (std::size_t t = 0; t < u.triangles.size(); ++t)
            for (int k = 0; k < 3; ++k) {
                const auto& tri = u.triangles[t];
                const std::uint32_t a = tri[std::size_t(k)], b = tri[std::size_t((k + 1) % 3)];
                std::int32_t sa = idOf(u.vertexSource[a]), sb = idOf(u.vertexSource[b]);
                glm::vec2 ua = u.uv[a], ub = u.uv[b];
                if (sa > sb) {
                    std::swap(sa, sb);
                    std::swap(ua, ub);
                }
                edges[{sa, sb}].push_back({ua, ub, mesh.normal(SurfaceMesh::FaceHandle(u.faceSource[t]))});
            }
        for (const auto& [key, sides] : edges) {
            if (sides.size() != 2) continue;
            const glm::vec2 a0 = sides[0].a, b0 = sides[0].b, a1 = sides[1].a, b1 = sides[1].b;
            if (glm::length(a0 - a1) + glm::length(b0 - b1) < 1e-6f) continue;  // same chart: no seam
            // Across a crease the light itself is discontinuous (a box's top and side): not a seam to hide.
            if (OpenMesh::dot(sides[0].normal, sides[1].normal) < kSmoothCos) continue;
            ++seamEdges;
            const float lengthTexels = std::max(glm::length(b0 - a0), glm::length(b1 - a1)) * float(image.size);
            const int n = std::max(2, int(std::ceil(4.0f * lengthTexels)) + 1);  // 4 per texel: see the header
            for (int s = 0; s < n; ++s) {
                const float t = (float(s) + 0.5f) / float(n);
                SeamSample sample{};
                sample.atlas = u.atlas;
                bilinear(image, a0 + t * (b0 - a0), sample.texels[0], sample.weights[0]);
                bilinear(image, a1 + t * (b1 - a1), sample.texels[1], sample.weights[1]);
                samples.push_back(sample);
            }
        }
    }
    return samples;
}

// The mean over the samples of both sides' channel sum, averaged.
double seamMean(const std::vector<SeamSample>& samples, const std::vector<LightmapImage>& images) {
    double mean = 0.0;
    for (const SeamSample& s : samples) {
        const glm::vec3 a = lookup(images[std::size_t(s.atlas)], s.texels[0], s.weights[0]);
        const glm::vec3 b = lookup(images[std::size_t(s.atlas)], s.texels[1], s.weights[1]);
        mean += double(a.x + a.y + a.z + b.x + b.y + b.z) / 2.0;
    }
    return samples.empty() ? 0.0 : mean / double(samples.size());
}

void measure(const std::vector<SeamSample>& samples, const std::vector<LightmapImage>& images, double& maxRel, double& meanRel) {
    // Relative to the local value, with a floor of 1% of the seams' mean so black corners do not dominate.
    const double floor = 0.01 * seamMean(samples, images);
    maxRel = meanRel = 0.0;
    for (const SeamSample& s : samples) {
        const glm::vec3 a = lookup(images[std::size_t(s.atlas)], s.texels[0], s.weights[0]);
        const glm::vec3 b = lookup(images[std::size_t(s.atlas)], s.texels[1], s.weights[1]);
        const double diff = std::abs(double(a.x + a.y + a.z) - double(b.x + b.y + b.z));
        const double local = std::max(double(a.x + a.y + a.z + b.x + b.y + b.z) / 2.0, floor);
        const double rel = local > 0.0 ? diff / local : 0.0;
        maxRel = std::max(maxRel, rel);
        meanRel += rel;
    }
    if (!samples.empty()) meanRel /= double(samples.size());
}

}  // namespace

SeamStats stitchSeams(const Scene& scene, const UvAtlas& atlas, std::vector<LightmapImage>& lightmaps, bool stitch, int sweeps) {
    SeamStats stats;
    const std::vector<SeamSample> samples = findSeamSamples(scene, atlas, lightmaps, stats.seamEdges);
    stats.samples = samples.size();
    measure(samples, lightmaps, stats.maxRelativeBefore, stats.meanRelativeBefore);
    if (stitch) {
        // Sweeps stop early once no sample pair differs by more than 1e-4 of the seams' mean (per channel).
        const float converged = float(1e-4 * seamMean(samples, lightmaps) / 3.0);
        for (int sweep = 0; sweep < sweeps; ++sweep) {
            float largest = 0.0f;
            for (const SeamSample& s : samples) {
                LightmapImage& image = lightmaps[std::size_t(s.atlas)];
                const glm::vec3 d = lookup(image, s.texels[0], s.weights[0]) - lookup(image, s.texels[1], s.weights[1]);
                largest = std::max({largest, std::abs(d.x), std::abs(d.y), std::abs(d.z)});
                float norm = 0.0f;
                for (int k = 0; k < 4; ++k) norm += s.weights[0][k] * s.weights[0][k] + s.weights[1][k] * s.weights[1][k];
                if (!(norm > 0.0f)) continue;
                // Kaczmarz: the smallest change to the eight texels that makes this sample pair agree.
                for (int k = 0; k < 4; ++k) {
                    image.irradianceOverPi[s.texels[0][k]] -= d * (s.weights[0][k] / norm);
                    image.irradianceOverPi[s.texels[1][k]] += d * (s.weights[1][k] / norm);
                }
            }
            stats.sweeps = sweep + 1;
            if (!(largest > converged)) break;
        }
        // Light cannot be negative; clamping after the sweeps keeps the projection's small overshoots out.
        for (LightmapImage& image : lightmaps)
            for (glm::vec3& v : image.irradianceOverPi) v = glm::max(v, glm::vec3(0.0f));
    }
    measure(samples, lightmaps, stats.maxRelativeAfter, stats.meanRelativeAfter);
    return stats;
}

}  // namespace hemibake
