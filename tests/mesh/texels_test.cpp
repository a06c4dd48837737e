// Texels: conservative coverage, sample positions on the surface (texel centre or closest chart point),
// the normal nudge, and agreement with the atlas' coverage count.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "mesh/gltf_loader.h"
#include "mesh/islands.h"
#include "mesh/scene_builder.h"
#include "mesh/texels.h"

namespace hemibake {
namespace {

// The nudge off the surface: 1e-5 × the scene's diagonal, wherever the scene sits (mesh/texels.h).
// The nudge: 1e-5 of the diagonal of the texel's island (mesh/islands.h; the float floor is far below that in
// these scenes, none far from its centre).
double nudgeFor(const Scene& scene, std::size_t instance, double relative = 1e-5) {
    const SceneIslands islands = SceneIslands::ofScene(scene);
    return relative * islands.bounds(islands.islandOfPart(instance)).diagonal();
}

// Checks every texel of every atlas: row-major unique order, valid face, the un-nudged sample lies on its face,
// the nudge is along the face normal, and the sample is the texel centre (inside) or a point on the boundary of
// the triangle within one texel of the centre (outside).
void expectConsistent(const Scene& scene, const UvAtlas& atlas, const std::vector<AtlasTexels>& texels) {
    ASSERT_EQ(texels.size(), atlas.atlases.size());
    for (std::size_t a = 0; a < texels.size(); ++a) {
        const AtlasTexels& t = texels[a];
        EXPECT_EQ(t.size, atlas.atlases[a].size);
        EXPECT_EQ(t.count(), atlas.atlases[a].coveredTexels);
        std::int64_t previous = -1;
        for (std::size_t k = 0; k < t.count(); ++k) {
            const std::int64_t index = std::int64_t(t.y[k]) * t.size + t.x[k];
            EXPECT_GT(index, previous);
            previous = index;
            const SurfaceMesh& mesh = scene.instances[std::size_t(t.instance[k])].mesh;
            const UnwrappedInstance& ui = atlas.instances[std::size_t(t.instance[k])];
            ASSERT_GE(t.face[k], 0);
            ASSERT_LT(std::size_t(t.face[k]), mesh.n_faces());
            // Find the unwrapped triangle of that face in this atlas.
            std::size_t tri = ui.faceSource.size();
            for (std::size_t i = 0; i < ui.faceSource.size(); ++i)
                if (ui.faceSource[i] == t.face[k]) tri = i;
            ASSERT_LT(tri, ui.faceSource.size());
            glm::dvec3 P[3];
            glm::dvec2 UV[3];
            for (int j = 0; j < 3; ++j) {
                const std::uint32_t v = ui.triangles[tri][std::size_t(j)];
                const auto p = mesh.point(SurfaceMesh::VertexHandle(ui.vertexSource[v]));
                P[j] = {p[0], p[1], p[2]};
                UV[j] = glm::dvec2(ui.uv[v]) * double(t.size);
            }
            const glm::dvec3 n = glm::normalize(glm::cross(P[1] - P[0], P[2] - P[0]));
            EXPECT_NEAR(glm::length(glm::dvec3(t.normal[k]) - n), 0.0, 1e-6);
            glm::dvec3 b = glm::dvec3(t.barycentric[k]);
            EXPECT_NEAR(b.x + b.y + b.z, 1.0, 1e-6);
            b /= b.x + b.y + b.z;  // stored in float
            EXPECT_GE(std::min({b.x, b.y, b.z}), -1e-7);
            const glm::dvec3 onSurface = b.x * P[0] + b.y * P[1] + b.z * P[2];
            const glm::dvec3 offset = t.position[k] - onSurface;
            EXPECT_NEAR(glm::dot(offset, n), nudgeFor(scene, std::size_t(t.instance[k])), 1e-9);
            EXPECT_NEAR(glm::length(offset - glm::dot(offset, n) * n), 0.0, 1e-6);
            const glm::dvec2 sampleUv = b.x * UV[0] + b.y * UV[1] + b.z * UV[2];
            const glm::dvec2 centre(t.x[k] + 0.5, t.y[k] + 0.5);
            if (t.centreInside[k]) {
                EXPECT_NEAR(glm::length(sampleUv - centre), 0.0, 1e-4);
            } else {
                // Stepped in from the chart edge: strictly inside its triangle, at most the inset further away.
                EXPECT_GT(std::min({b.x, b.y, b.z}), 1e-6);
                EXPECT_LE(glm::length(sampleUv - centre), std::sqrt(0.5) + TexelSettings{}.borderInsetTexels + 1e-4);
            }
        }
    }
}

TEST(MeshTexels, UnitQuadMatchesTheAnalyticGrid) {
    SceneBuilder b;
    const int m = b.addMaterial(glm::vec3(0.5f));
    b.addQuad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, m);
    const Scene scene = b.build();
    UnwrapSettings s;
    s.texelsPerUnit = 64.0;
    const UvAtlas atlas = unwrapScene(scene, s);
    ASSERT_EQ(atlas.atlases.size(), 1u);
    const auto texels = computeTexels(scene, atlas);
    const AtlasTexels& t = texels[0];
    ASSERT_EQ(t.count(), 64u * 64u);  // exactly the quad's 64 × 64 texels, no neighbours
    expectConsistent(scene, atlas, texels);
    std::set<std::pair<int, int>> grid;
    std::map<std::pair<int, int>, glm::dvec3> byTexel;
    for (std::size_t k = 0; k < t.count(); ++k) {
        EXPECT_TRUE(t.centreInside[k]);
        EXPECT_EQ(t.normal[k], glm::vec3(0, 0, 1));
        EXPECT_EQ(t.instance[k], 0);
        const glm::dvec3 p = t.position[k];
        // Texel centres sit at (i + 0.5)/64 on the quad, lifted by the nudge.
        const double gi = p.x * 64.0 - 0.5, gj = p.y * 64.0 - 0.5;
        EXPECT_NEAR(gi, std::round(gi), 1e-4);
        EXPECT_NEAR(gj, std::round(gj), 1e-4);
        EXPECT_NEAR(p.z, nudgeFor(scene, 0), 1e-12);
        grid.insert({int(std::lround(gi)), int(std::lround(gj))});
        byTexel[{t.x[k], t.y[k]}] = p;
    }
    EXPECT_EQ(grid.size(), 64u * 64u);
    EXPECT_EQ(grid.begin()->first, 0);
    EXPECT_EQ(grid.rbegin()->first, 63);
    // Neighbouring texels are one texel (1/64 m) apart on the surface.
    for (const auto& [xy, p] : byTexel) {
        auto right = byTexel.find({xy.first + 1, xy.second});
        if (right != byTexel.end()) {
            EXPECT_NEAR(glm::length(glm::dvec2(right->second - p)), 1.0 / 64.0, 1e-6);
        }
        auto down = byTexel.find({xy.first, xy.second + 1});
        if (down != byTexel.end()) {
            EXPECT_NEAR(glm::length(glm::dvec2(down->second - p)), 1.0 / 64.0, 1e-6);
        }
    }
    // No nudge on request.
    TexelSettings flat;
    flat.normalOffsetRelative = 0.0;
    const auto unnudged = computeTexels(scene, atlas, flat);
    for (const auto& p : unnudged[0].position) EXPECT_EQ(p.z, 0.0);
}

// Rows (and columns) a UV triangle overlaps by more than the coverage shrink.
std::set<long> spannedRows(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, bool columns) {
    std::set<long> rows;
    forEachTouchedTexel(a, b, c, kCoverageShrinkTexels, [&](long x, long y) { rows.insert(columns ? x : y); });
    return rows;
}

TEST(MeshTexels, SliversGetATexelInEveryRowTheyCross) {
    SceneBuilder b;
    const int m = b.addMaterial(glm::vec3(0.5f));
    // Thin slivers (at most ~0.2 texel wide at 64 texels/m): one upright, one diagonal.
    b.addTriangles({{0, 0, 0}, {0.003, 0, 0}, {0.0015, 1, 0}}, {{0, 1, 2}}, m, "upright");
    b.addTriangles({{2, 0, 0}, {3, 1, 0}, {2.997, 1.002, 0}}, {{0, 1, 2}}, m, "diagonal");
    const Scene scene = b.build();
    UnwrapSettings s;
    s.texelsPerUnit = 64.0;
    s.allowRotation = false;  // keep them crossing many rows
    const UvAtlas atlas = unwrapScene(scene, s);
    const auto texels = computeTexels(scene, atlas);
    expectConsistent(scene, atlas, texels);
    for (std::size_t inst = 0; inst < 2; ++inst) {
        const UnwrappedInstance& ui = atlas.instances[inst];
        const AtlasTexels& t = texels[std::size_t(ui.atlas)];
        const double S = t.size;
        const auto& tri = ui.triangles[0];
        const glm::dvec2 A = glm::dvec2(ui.uv[tri[0]]) * S, B = glm::dvec2(ui.uv[tri[1]]) * S, C = glm::dvec2(ui.uv[tri[2]]) * S;
        std::set<long> rows, cols;
        std::size_t inside = 0;
        for (std::size_t k = 0; k < t.count(); ++k) {
            if (t.instance[k] != int(inst)) continue;
            rows.insert(t.y[k]);
            cols.insert(t.x[k]);
            inside += t.centreInside[k];
        }
        EXPECT_EQ(rows, spannedRows(A, B, C, false)) << "instance " << inst;
        EXPECT_EQ(cols, spannedRows(A, B, C, true)) << "instance " << inst;
        EXPECT_GE(rows.size(), 60u);  // ~64 rows at 64 texels per metre
        EXPECT_LT(inside, rows.size());  // most centres miss the sliver: samples snap onto it
    }
}

TEST(MeshTexels, CornellBoxTexelsAreConsistent) {
    const Scene scene = loadGltf(std::string(HEMIBAKE_SHARED_DIR) + "/scenes/cornell_box.gltf");
    UnwrapSettings s;
    s.texelsPerUnit = 64.0;
    const UvAtlas atlas = unwrapScene(scene, s);
    const auto texels = computeTexels(scene, atlas);
    expectConsistent(scene, atlas, texels);
    std::size_t total = 0, outside = 0;
    std::set<int> instances;
    for (const auto& t : texels) {
        total += t.count();
        for (std::size_t k = 0; k < t.count(); ++k) {
            outside += t.centreInside[k] ? 0 : 1;
            instances.insert(t.instance[k]);
        }
    }
    EXPECT_EQ(total, atlas.stats.coveredTexels);
    EXPECT_EQ(instances.size(), scene.instances.size());
    EXPECT_GT(outside, 0u);  // edge texels whose centres fall outside the charts
    EXPECT_LT(outside, total / 5);
}

}  // namespace
}  // namespace hemibake
