// Packing: charts never overlap, keep the requested padding and border, stay in [0,1], keep their texel
// density, spill into further atlases, shrink when too large, and fill a Cornell box atlas well.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "mesh/errors.h"
#include "mesh/gltf_loader.h"
#include "mesh/pack.h"
#include "mesh/scene_builder.h"
#include "mesh/uv_atlas.h"
#include "support/test_meshes.h"

namespace hemibake {
namespace {

using test::addSphere;
using test::addTorus;
using test::Tri;

// A closed box as one instance (8 shared corners).
void addClosedBox(SceneBuilder& b, int m, glm::dvec3 lo, glm::dvec3 hi) {
    std::vector<glm::dvec3> p;
    for (int i = 0; i < 8; ++i) p.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
    const int q[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    std::vector<Tri> t;
    for (const auto& f : q) {
        t.push_back({f[0], f[1], f[2]});
        t.push_back({f[0], f[2], f[3]});
    }
    b.addTriangles(p, t, m, "box");
}

Scene mixedScene() {
    SceneBuilder b;
    const int m = b.addMaterial(glm::vec3(0.5f));
    addSphere(b, m, 16, 8, 0.5, {3, 0, 0});
    addTorus(b, m, 24, 12, 1.0, 0.3);
    addClosedBox(b, m, {-2, 0, 0}, {-1.2, 0.4, 0.7});
    b.addBox({0, 0, 0}, {2, 1.5, 1.0}, m, true);  // six quads, one instance each
    return b.build();
}

// Rasterizes every chart of the final atlas (float UVs, as any consumer sees them) into per-atlas ownership
// bitmaps and checks: no texel claimed by two charts; every other chart's texels at least `padding` free
// texels away (Chebyshev); `border` free texels at the edges; all UVs in [0,1].
void expectDisjointPadded(const UvAtlas& atlas, int padding, int border) {
    for (std::size_t a = 0; a < atlas.atlases.size(); ++a) {
        const int S = atlas.atlases[a].size;
        std::vector<int> owner(std::size_t(S) * std::size_t(S), -1);
        std::size_t conflicts = 0, covered = 0;
        for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
            const AtlasChart& ac = atlas.charts[c];
            if (ac.atlas != int(a)) continue;
            const UnwrappedInstance& ui = atlas.instances[std::size_t(ac.instance)];
            for (std::uint32_t t = ac.firstTriangle; t < ac.firstTriangle + ac.triangleCount; ++t) {
                glm::dvec2 p[3];
                for (int k = 0; k < 3; ++k) {
                    const glm::vec2 uv = ui.uv[ui.triangles[t][std::size_t(k)]];
                    ASSERT_GE(uv.x, 0.0f);
                    ASSERT_LE(uv.x, 1.0f);
                    ASSERT_GE(uv.y, 0.0f);
                    ASSERT_LE(uv.y, 1.0f);
                    p[k] = glm::dvec2(uv) * double(S);
                }
                forEachTouchedTexel(p[0], p[1], p[2], kCoverageShrinkTexels, [&](long x, long y) {
                    ASSERT_TRUE(x >= border && y >= border && x < S - border && y < S - border)
                        << "texel " << x << "," << y << " in the border of atlas " << a << " (size " << S << ")";
                    int& o = owner[std::size_t(y) * std::size_t(S) + std::size_t(x)];
                    if (o < 0) {
                        o = int(c);
                        ++covered;
                    } else if (o != int(c)) {
                        ++conflicts;
                    }
                });
            }
        }
        EXPECT_EQ(conflicts, 0u) << "atlas " << a;
        EXPECT_EQ(covered, atlas.atlases[a].coveredTexels);
        std::size_t tooClose = 0;
        for (int y = 0; y < S; ++y)
            for (int x = 0; x < S; ++x) {
                const int o = owner[std::size_t(y) * std::size_t(S) + std::size_t(x)];
                if (o < 0) continue;
                for (int dy = -padding; dy <= padding; ++dy)
                    for (int dx = -padding; dx <= padding; ++dx) {
                        const int xx = x + dx, yy = y + dy;
                        if (xx < 0 || yy < 0 || xx >= S || yy >= S) continue;
                        const int q = owner[std::size_t(yy) * std::size_t(S) + std::size_t(xx)];
                        if (q >= 0 && q != o) ++tooClose;
                    }
            }
        EXPECT_EQ(tooClose, 0u) << "atlas " << a << ": texels of different charts closer than " << padding;
    }
    EXPECT_EQ(atlas.stats.overlappingTexels, 0u);
}

// UV area in texels² over surface area = density², for every chart not scaled down.
void expectDensity(const Scene& scene, const UvAtlas& atlas, double texelsPerUnit) {
    for (const AtlasChart& ac : atlas.charts) {
        if (ac.scaledDown) continue;
        const UnwrappedInstance& ui = atlas.instances[std::size_t(ac.instance)];
        const SurfaceMesh& mesh = scene.instances[std::size_t(ac.instance)].mesh;
        const double S = atlas.atlases[std::size_t(ac.atlas)].size;
        double uvArea = 0.0, area = 0.0;
        for (std::uint32_t t = ac.firstTriangle; t < ac.firstTriangle + ac.triangleCount; ++t) {
            const auto& tri = ui.triangles[t];
            const glm::dvec2 a = glm::dvec2(ui.uv[tri[0]]) * S, b = glm::dvec2(ui.uv[tri[1]]) * S, c = glm::dvec2(ui.uv[tri[2]]) * S;
            uvArea += 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
            area += mesh.faceArea(SurfaceMesh::FaceHandle(ui.faceSource[t]));
        }
        EXPECT_NEAR(std::sqrt(uvArea / area) / texelsPerUnit, 1.0, 1e-3);
        EXPECT_NEAR(ac.texelsPerUnit, texelsPerUnit, 1e-9);
    }
}

TEST(MeshPack, TouchedTexelsAreExact) {
    std::set<std::pair<long, long>> cells;
    auto collect = [&](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, double shrink) {
        cells.clear();
        forEachTouchedTexel(a, b, c, shrink, [&](long x, long y) { EXPECT_TRUE(cells.insert({x, y}).second); });
        return cells.size();
    };
    // A 2×2 texel square (two triangles) aligned with the grid: 4 texels each half-covered → 3 per triangle.
    EXPECT_EQ(collect({1, 1}, {3, 1}, {3, 3}, kCoverageShrinkTexels), 3u);
    EXPECT_EQ(collect({1, 1}, {3, 3}, {1, 3}, kCoverageShrinkTexels), 3u);
    // Closed coverage (no shrink) also counts texels the triangle merely touches at an edge or corner.
    EXPECT_EQ(collect({1, 1}, {3, 1}, {3, 3}, 0.0), 13u);
    // Inside a single texel.
    EXPECT_EQ(collect({5.2, 7.1}, {5.8, 7.2}, {5.5, 7.9}, kCoverageShrinkTexels), 1u);
    // A sliver 0.01 texel wide crossing 10 rows: at least one texel in every row.
    collect({0.50, 0.20}, {0.51, 0.20}, {3.7, 9.8}, kCoverageShrinkTexels);
    std::set<long> rows;
    for (const auto& c : cells) rows.insert(c.second);
    EXPECT_EQ(rows, (std::set<long>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
    // No texel that intersects the triangle is missed (brute force check).
    const glm::dvec2 A{0.3, 0.4}, B{7.9, 2.2}, C{2.6, 6.7};
    collect(A, B, C, 0.0);
    for (long y = -1; y < 9; ++y)
        for (long x = -1; x < 9; ++x) {
            // Texel ∩ triangle ≠ ∅ iff some point of a fine grid in the texel is inside (up to grid resolution).
            bool hit = false;
            for (int i = 0; i <= 40 && !hit; ++i)
                for (int j = 0; j <= 40 && !hit; ++j) {
                    const glm::dvec2 p(double(x) + i / 40.0, double(y) + j / 40.0);
                    auto side = [&](glm::dvec2 u, glm::dvec2 v) { return (v.x - u.x) * (p.y - u.y) - (v.y - u.y) * (p.x - u.x); };
                    hit = side(A, B) >= 0 && side(B, C) >= 0 && side(C, A) >= 0;
                }
            if (hit) {
                EXPECT_TRUE(cells.count({x, y})) << x << "," << y;
            }
        }
}

TEST(MeshPack, ChartsNeverOverlapAndKeepPadding) {
    const Scene scene = mixedScene();
    for (int padding : {2, 4}) {
        for (bool rotate : {true, false}) {
            UnwrapSettings s;
            s.texelsPerUnit = 48.0;
            s.paddingTexels = padding;
            s.borderTexels = 1;
            s.allowRotation = rotate;
            const UvAtlas atlas = unwrapScene(scene, s);
            ASSERT_EQ(atlas.atlases.size(), 1u);
            EXPECT_EQ(atlas.stats.badUvTriangles, 0u);
            expectDisjointPadded(atlas, padding, 1);
            expectDensity(scene, atlas, 48.0);
            std::printf("[ packing  ] mixed scene, padding %d, rotation %d: %zu charts, atlas %d, utilization %.3f\n", padding,
                        int(rotate), atlas.charts.size(), atlas.atlases[0].size, atlas.stats.utilization);
        }
    }
}

TEST(MeshPack, SpillsIntoFurtherAtlasesKeepingInstancesTogether) {
    SceneBuilder b;
    const int m = b.addMaterial(glm::vec3(0.5f));
    for (int i = 0; i < 24; ++i) {
        const double sx = 0.3 + 0.05 * (i % 7), sy = 0.2 + 0.07 * (i % 5), sz = 0.25 + 0.04 * (i % 3);
        addClosedBox(b, m, {2.0 * i, 0, 0}, {2.0 * i + sx, sy, sz});
    }
    const Scene scene = b.build();
    UnwrapSettings s;
    s.texelsPerUnit = 64.0;
    s.maxAtlasSize = 128;
    const UvAtlas atlas = unwrapScene(scene, s);
    EXPECT_GE(atlas.atlases.size(), 3u);
    for (const AtlasPage& page : atlas.atlases) EXPECT_LE(page.size, 128);
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const UnwrappedInstance& ui = atlas.instances[i];
        ASSERT_GE(ui.atlas, 0);
        EXPECT_EQ(ui.chartCount, 6u);
        for (std::uint32_t c = ui.firstChart; c < ui.firstChart + ui.chartCount; ++c) {
            EXPECT_EQ(atlas.charts[c].atlas, ui.atlas);
            EXPECT_EQ(atlas.charts[c].instance, int(i));
            EXPECT_FALSE(atlas.charts[c].scaledDown);
        }
    }
    expectDisjointPadded(atlas, s.paddingTexels, s.borderTexels);
    expectDensity(scene, atlas, 64.0);
    EXPECT_TRUE(atlas.warnings.empty());
}

TEST(MeshPack, OversizedChartIsScaledDownWithWarning) {
    SceneBuilder b;
    const int m = b.addMaterial(glm::vec3(0.5f));
    b.addQuad({0, 0, 0}, {10, 0, 0}, {10, 0, -4}, {0, 0, -4}, m, "floor");  // 1280 × 512 texels wanted
    b.addQuad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, m, "small");
    const Scene scene = b.build();
    UnwrapSettings s;
    s.texelsPerUnit = 128.0;
    s.maxAtlasSize = 256;
    const UvAtlas atlas = unwrapScene(scene, s);
    ASSERT_FALSE(atlas.warnings.empty());
    EXPECT_GE(atlas.stats.scaledDownCharts, 1u);
    const AtlasChart& big = atlas.charts[atlas.instances[0].firstChart];
    EXPECT_TRUE(big.scaledDown);
    EXPECT_LT(big.texelsPerUnit, 128.0 * 254.0 / 1280.0 + 1e-9);
    EXPECT_GT(big.texelsPerUnit, 0.8 * 128.0 * 254.0 / 1280.0);
    EXPECT_LE(big.width, 256 - 2 * s.borderTexels);
    for (const AtlasPage& page : atlas.atlases) EXPECT_LE(page.size, 256);
    expectDisjointPadded(atlas, s.paddingTexels, s.borderTexels);
}

// A 100 km floor at 8 texels/m wants 800,000² texels: the packer must shrink it to the atlas before it rasterizes
// (it used to rasterize at full size first: std::bad_alloc, "hemibake: out of memory" from a bake).
TEST(MeshPack, ChartFarLargerThanTheAtlasIsShrunkBeforeRasterizing) {
    const std::vector<glm::dvec2> floor{{0, 0}, {1e5, 0}, {1e5, 1e5}, {0, 1e5}};
    const std::vector<std::array<std::int32_t, 3>> tris{{0, 1, 2}, {0, 2, 3}};
    std::vector<PackChartInput> in{{floor, tris, 0}};
    PackSettings s;
    s.texelsPerUnit = 8.0;
    s.maxAtlasSize = 1024;
    const PackResult r = packCharts(in, s);
    ASSERT_EQ(r.atlasSize.size(), 1u);
    EXPECT_LE(r.atlasSize[0], 1024);
    const PackedChart& c = r.charts[0];
    EXPECT_TRUE(c.scaledDown);
    EXPECT_EQ(r.scaledDownCharts, 1u);
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("scaled down to fit a 1024 atlas"), std::string::npos) << r.warnings[0];
    EXPECT_LE(std::max(c.width, c.height), 1024 - 2 * s.borderTexels);
    // Shrunk to the atlas, not far below it: within 3 % of the largest square that fits.
    EXPECT_GT(c.scale * 1e5, 0.97 * (1024 - 2 * s.borderTexels - 2));
    for (const auto& uv : floor) {
        const glm::dvec2 t = c.toTexels(uv);
        EXPECT_GE(std::min(t.x, t.y), double(s.borderTexels) - 1e-9);
        EXPECT_LE(std::max(t.x, t.y), double(r.atlasSize[0] - s.borderTexels) + 1e-9);
    }
}

// Found by fuzz_mesh_unwrap: an instance with more charts than one atlas holds once each is down to a texel plus its
// padding used to be left out of every atlas (its charts at atlas −1; unwrapScene then indexed atlas −1). It is an
// error now, naming the instance, the charts and the settings to change.
TEST(MeshPack, GroupThatCannotShareOneAtlasIsAnError) {
    std::vector<glm::dvec2> uv;
    std::vector<std::array<std::int32_t, 3>> tris;
    for (int i = 0; i < 11; ++i) {  // 11 separate unit triangles: each needs 1 + 4 texels, 14 fit a 16-atlas row
        uv.insert(uv.end(), {{0, 0}, {1, 0}, {0, 1}});
        tris.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    }
    std::vector<PackChartInput> in;
    for (int i = 0; i < 11; ++i)
        in.push_back({std::span<const glm::dvec2>(uv).subspan(std::size_t(3 * i), 3), std::span(tris).subspan(0, 1), 7});
    PackSettings s;
    s.texelsPerUnit = 1.0;
    s.maxAtlasSize = 16;
    s.paddingTexels = 4;
    try {
        packCharts(in, s);
        FAIL() << "11 charts with 4 texels of padding fit a 16-texel atlas?";
    } catch (const PackError& e) {
        EXPECT_EQ(e.group(), 7);
        EXPECT_EQ(e.charts(), 11u);
        EXPECT_EQ(std::string(e.what()), "its 11 charts do not fit one 16-texel atlas with 4 texels of padding between them, "
                                         "however small (raise the maximum atlas size or lower the padding)");
    }
    s.paddingTexels = 0;  // without padding they fit
    const PackResult r = packCharts(in, s);
    for (const PackedChart& c : r.charts) EXPECT_EQ(c.atlas, 0);

    // Through unwrapScene: an input error naming the file and the instance.
    SceneBuilder b("confetti.gltf");
    const int m = b.addMaterial(glm::vec3(0.5f));
    std::vector<glm::dvec3> p;
    std::vector<Tri> t;
    for (int i = 0; i < 11; ++i) {  // triangles facing 11 different ways: 11 charts
        const double a = 2.0 * M_PI * i / 11.0;
        const glm::dvec3 o(3.0 * i, 0.0, 0.0), u(std::cos(a), std::sin(a), 0.0);
        p.insert(p.end(), {o, o + u, o + glm::dvec3(0, 0, 1)});
        t.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    }
    b.addTriangles(p, t, m, "confetti");
    UnwrapSettings us;
    us.texelsPerUnit = 1.0;
    us.maxAtlasSize = 16;
    us.paddingTexels = 4;
    try {
        unwrapScene(b.build(), us);
        FAIL() << "expected an InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("confetti.gltf: node 'confetti' (mesh 0 primitive 0): its 11 charts do not fit one "
                                              "16-texel atlas", 0), 0u) << e.what();
    }
}

TEST(MeshPack, ChartsAreTurnedToTheirMinimalBoundingBox) {
    // A 1 m × 0.25 m rectangle turned 30° in the ground plane: packed as 64 × 16 texels, not its 30° bbox.
    SceneBuilder b;
    const int m = b.addMaterial(glm::vec3(0.5f));
    const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
    auto at = [&](double x, double z) { return glm::dvec3(c * x - s * z, 0.0, -(s * x + c * z)); };
    b.addQuad(at(0, 0), at(1, 0), at(1, 0.25), at(0, 0.25), m);
    const Scene scene = b.build();
    UnwrapSettings settings;
    settings.texelsPerUnit = 64.0;
    const UvAtlas atlas = unwrapScene(scene, settings);
    ASSERT_EQ(atlas.charts.size(), 1u);
    const AtlasChart& ch = atlas.charts[0];
    EXPECT_EQ(std::max(ch.width, ch.height), 64);
    EXPECT_EQ(std::min(ch.width, ch.height), 16);
    EXPECT_EQ(atlas.atlases[0].coveredTexels, 64u * 16u);
}

TEST(MeshPack, CornellBoxUtilization) {
    const Scene scene = loadGltf(std::string(HEMIBAKE_SHARED_DIR) + "/scenes/cornell_box.gltf");
    for (double density : {128.0, 200.0}) {
        UnwrapSettings s;
        s.texelsPerUnit = density;
        const UvAtlas atlas = unwrapScene(scene, s);
        ASSERT_EQ(atlas.atlases.size(), 1u);
        std::printf("[ cornell  ] %.0f texels/m, padding %d: %zu charts (%zu planar, %zu lscm), atlas %d², "
                    "covered %llu, utilization %.3f\n",
                    density, s.paddingTexels, atlas.stats.charts, atlas.stats.planarCharts, atlas.stats.lscmCharts,
                    atlas.atlases[0].size, (unsigned long long)atlas.stats.coveredTexels, atlas.stats.utilization);
        EXPECT_GE(atlas.stats.utilization, 0.60) << density << " texels per metre";
        EXPECT_EQ(atlas.stats.badUvTriangles, 0u);
        expectDisjointPadded(atlas, s.paddingTexels, s.borderTexels);
        expectDensity(scene, atlas, density);
    }
}

TEST(MeshPack, PackChartsDirectly) {
    // Two 10×10 texel squares and an L-shape at 1 texel per unit; power-of-two sizes.
    const std::vector<glm::dvec2> square{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
    const std::vector<std::array<std::int32_t, 3>> squareTris{{0, 1, 2}, {0, 2, 3}};
    const std::vector<glm::dvec2> ell{{0, 0}, {20, 0}, {20, 5}, {5, 5}, {5, 20}, {0, 20}};
    const std::vector<std::array<std::int32_t, 3>> ellTris{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}};
    std::vector<PackChartInput> in{{square, squareTris, 0}, {square, squareTris, 1}, {ell, ellTris, 2}};
    PackSettings s;
    s.texelsPerUnit = 1.0;
    s.powerOfTwo = true;
    const PackResult r = packCharts(in, s);
    ASSERT_EQ(r.atlasSize.size(), 1u);
    EXPECT_EQ(r.atlasSize[0], 32);  // the L (20×20) and two squares nest into 32²
    EXPECT_EQ(r.atlasFootprintTexels[0], 100u + 100u + 175u);
    for (std::size_t i = 0; i < in.size(); ++i) {
        EXPECT_EQ(r.charts[i].atlas, 0);
        EXPECT_NEAR(r.charts[i].scale, 1.0, 0.0);
        // Rotations are by quarter turns here and offsets land corners on texel corners.
        for (const auto& uv : in[i].uv) {
            const glm::dvec2 t = r.charts[i].toTexels(uv);
            EXPECT_NEAR(t.x, std::round(t.x), 1e-9);
            EXPECT_NEAR(t.y, std::round(t.y), 1e-9);
        }
    }
    EXPECT_NEAR(r.utilization(), 375.0 / 1024.0, 1e-12);
}

TEST(MeshPack, UnwrappedMeshMapsBackToTheInput) {
    const Scene scene = mixedScene();
    const UvAtlas atlas = unwrapScene(scene, {});
    ASSERT_EQ(atlas.instances.size(), scene.instances.size());
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const SurfaceMesh& mesh = scene.instances[i].mesh;
        const UnwrappedInstance& ui = atlas.instances[i];
        ASSERT_EQ(ui.uv.size(), ui.vertexSource.size());
        ASSERT_EQ(ui.triangles.size(), ui.faceSource.size());
        EXPECT_EQ(ui.triangles.size(), mesh.n_faces());  // every face exactly once
        std::set<int> faces(ui.faceSource.begin(), ui.faceSource.end());
        EXPECT_EQ(faces.size(), mesh.n_faces());
        EXPECT_GE(ui.uv.size(), mesh.n_vertices());  // seams duplicate vertices
        // Unwrapped triangle t has the corners of its source face, in the same cyclic order (same winding).
        for (std::size_t t = 0; t < ui.triangles.size(); ++t) {
            std::vector<int> src;
            for (auto v : mesh.fv_range(SurfaceMesh::FaceHandle(ui.faceSource[t]))) src.push_back(v.idx());
            const int a = ui.vertexSource[ui.triangles[t][0]], b2 = ui.vertexSource[ui.triangles[t][1]],
                      c = ui.vertexSource[ui.triangles[t][2]];
            bool rotation = false;
            for (int k = 0; k < 3; ++k)
                rotation = rotation || (src[std::size_t(k)] == a && src[std::size_t((k + 1) % 3)] == b2 && src[std::size_t((k + 2) % 3)] == c);
            EXPECT_TRUE(rotation) << "instance " << i << " triangle " << t;
            // Never flipped or degenerate: positive signed area in (u, v), at least a texel-scale fraction.
            const glm::dvec2 p0 = ui.uv[ui.triangles[t][0]], p1 = ui.uv[ui.triangles[t][1]], p2 = ui.uv[ui.triangles[t][2]];
            const double S = atlas.atlases[std::size_t(ui.atlas)].size;
            const double uvArea = 0.5 * ((p1.x - p0.x) * (p2.y - p0.y) - (p1.y - p0.y) * (p2.x - p0.x)) * S * S;
            const double texelArea = mesh.faceArea(SurfaceMesh::FaceHandle(ui.faceSource[t])) * 128.0 * 128.0;
            EXPECT_GT(uvArea, 0.5 * texelArea);
        }
        // Chart runs tile the unwrapped arrays; within a chart an input vertex appears once.
        std::uint32_t nextVertex = 0, nextTriangle = 0;
        for (std::uint32_t c = ui.firstChart; c < ui.firstChart + ui.chartCount; ++c) {
            const AtlasChart& ac = atlas.charts[c];
            EXPECT_EQ(ac.firstVertex, nextVertex);
            EXPECT_EQ(ac.firstTriangle, nextTriangle);
            nextVertex += ac.vertexCount;
            nextTriangle += ac.triangleCount;
            std::set<int> sources;
            for (std::uint32_t v = ac.firstVertex; v < ac.firstVertex + ac.vertexCount; ++v)
                EXPECT_TRUE(sources.insert(ui.vertexSource[v]).second);
            for (std::uint32_t t = ac.firstTriangle; t < ac.firstTriangle + ac.triangleCount; ++t)
                for (std::uint32_t v : ui.triangles[t]) {
                    EXPECT_GE(v, ac.firstVertex);
                    EXPECT_LT(v, ac.firstVertex + ac.vertexCount);
                }
            // The instance rectangle holds every chart.
            EXPECT_GE(ac.x, ui.rect[0]);
            EXPECT_GE(ac.y, ui.rect[1]);
            EXPECT_LE(ac.x + ac.width, ui.rect[0] + ui.rect[2]);
            EXPECT_LE(ac.y + ac.height, ui.rect[1] + ui.rect[3]);
        }
        EXPECT_EQ(nextVertex, ui.uv.size());
        EXPECT_EQ(nextTriangle, ui.triangles.size());
    }
}

TEST(MeshPack, ExistingLightmapUvsAreKeptOnRequest) {
    SceneBuilder b;
    const int m = b.addMaterial(glm::vec3(0.5f));
    b.addQuad({0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}, m, "authored");
    b.addQuad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, m, "wrapping");
    b.addQuad({0, 0, 2}, {1, 0, 2}, {1, 1, 2}, {0, 1, 2}, m, "plain");
    Scene scene = b.build();
    // Authored UVs for the first quad: it fills the left half of its texture (u ∈ [0, 0.5], v ∈ [0, 1]).
    for (auto v : scene.instances[0].mesh.vertices()) {
        const auto p = scene.instances[0].mesh.point(v);
        scene.instances[0].mesh.lightmapUv(v) = {float(p[0] * 0.25), float(1.0 - p[1])};
    }
    scene.instances[0].hasLightmapUv = true;
    for (auto v : scene.instances[1].mesh.vertices()) scene.instances[1].mesh.lightmapUv(v) = {2.5f, 0.0f};  // outside [0,1]
    scene.instances[1].hasLightmapUv = true;

    UnwrapSettings s;
    s.texelsPerUnit = 32.0;
    s.keepExistingUv = true;
    const UvAtlas atlas = unwrapScene(scene, s);
    EXPECT_EQ(atlas.stats.existingUvInstances, 1u);
    const UnwrappedInstance& kept = atlas.instances[0];
    EXPECT_TRUE(kept.existingUv);
    ASSERT_EQ(kept.uv.size(), scene.instances[0].mesh.n_vertices());
    for (std::size_t v = 0; v < kept.uv.size(); ++v) {
        EXPECT_EQ(kept.vertexSource[v], int(v));
        const auto uv = scene.instances[0].mesh.lightmapUv(SurfaceMesh::VertexHandle(int(v)));
        EXPECT_EQ(kept.uv[v], glm::vec2(uv[0], uv[1]));
    }
    // Its own atlas, sized for the requested mean density: 2 m² over half the texture at 32 texels/m → 64².
    EXPECT_NE(kept.atlas, atlas.instances[2].atlas);
    EXPECT_EQ(atlas.atlases[std::size_t(kept.atlas)].size, 64);
    EXPECT_EQ(atlas.atlases[std::size_t(kept.atlas)].coveredTexels, 32u * 64u);
    // Bad existing UVs are replaced, with a warning; the rest is unwrapped as usual.
    EXPECT_FALSE(atlas.instances[1].existingUv);
    EXPECT_FALSE(atlas.warnings.empty());
    EXPECT_FALSE(atlas.instances[2].existingUv);
    expectDisjointPadded(atlas, 0, 0);
    // Without the setting every instance is unwrapped.
    s.keepExistingUv = false;
    EXPECT_EQ(unwrapScene(scene, s).stats.existingUvInstances, 0u);
}

}  // namespace
}  // namespace hemibake
