// Parameterization: no flipped or degenerate UV triangles, exact planar projection, LSCM isometric on
// developable surfaces, Sander stretch as defined, and the split / per-triangle fallback when LSCM fails.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "mesh/parameterize.h"
#include "mesh/scene_builder.h"
#include "support/test_meshes.h"

namespace hemibake {
namespace {

using test::Tri;
using test::singleMesh;
using test::torus;
using test::uvSphere;

// A strip of a cylinder (radius 1, height 1.5) spanning `degrees`, nu × nh quads: developable.
Scene cylinderStrip(double degrees, int nu, int nh) {
    std::vector<glm::dvec3> p;
    for (int j = 0; j <= nh; ++j)
        for (int i = 0; i <= nu; ++i) {
            const double a = degrees * M_PI / 180.0 * i / nu;
            p.push_back({std::cos(a), 1.5 * j / nh, -std::sin(a)});
        }
    std::vector<Tri> t;
    for (int j = 0; j < nh; ++j)
        for (int i = 0; i < nu; ++i) {
            const int a = j * (nu + 1) + i;
            t.push_back({a, a + 1, a + nu + 2});
            t.push_back({a, a + nu + 2, a + nu + 1});
        }
    return singleMesh(p, t);
}

ChartSet oneChart(const SurfaceMesh& mesh, const std::vector<std::int32_t>& faces) {
    ChartSet cs;
    cs.faceChart.assign(mesh.n_faces(), -1);
    cs.chartFaceStart = {0, std::uint32_t(faces.size())};
    cs.chartFaces = faces;
    for (int f : faces) cs.faceChart[std::size_t(f)] = 0;
    cs.planar = {0};
    cs.normal = {glm::dvec3(0, 0, 1)};
    cs.areaM2 = {0.0};
    return cs;
}

double area3d(const SurfaceMesh& mesh, const ParamChart& c, std::size_t t) {
    glm::dvec3 p[3];
    for (int k = 0; k < 3; ++k) {
        const auto q = mesh.point(SurfaceMesh::VertexHandle(c.vertices[std::size_t(c.triangles[t][std::size_t(k)])]));
        p[k] = {q[0], q[1], q[2]};
    }
    return 0.5 * glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
}

double areaUv(const ParamChart& c, std::size_t t) {
    const glm::dvec2 a = c.uv[std::size_t(c.triangles[t][0])], b = c.uv[std::size_t(c.triangles[t][1])],
                     d = c.uv[std::size_t(c.triangles[t][2])];
    return 0.5 * ((b.x - a.x) * (d.y - a.y) - (b.y - a.y) * (d.x - a.x));
}

// Every face exactly once, local indexing consistent with the mesh, no flipped/degenerate UV triangle,
// each chart's UV area equal to its surface area (1 UV unit = 1 m).
void expectValid(const SurfaceMesh& mesh, const ParameterizationResult& r, double minRatio = 0.05) {
    std::vector<int> seen(mesh.n_faces(), 0);
    for (const ParamChart& c : r.charts) {
        ASSERT_EQ(c.faces.size(), c.triangles.size());
        ASSERT_EQ(c.uv.size(), c.vertices.size());
        double a3 = 0.0, auv = 0.0;
        for (std::size_t t = 0; t < c.faces.size(); ++t) {
            ++seen[std::size_t(c.faces[t])];
            std::multiset<int> want, got;
            for (auto v : mesh.fv_range(SurfaceMesh::FaceHandle(c.faces[t]))) want.insert(v.idx());
            for (int k = 0; k < 3; ++k) got.insert(c.vertices[std::size_t(c.triangles[t][std::size_t(k)])]);
            EXPECT_EQ(want, got);
            const double A = area3d(mesh, c, t), U = areaUv(c, t);
            EXPECT_GT(U, minRatio * A) << paramMethodName(c.method) << " chart, face " << c.faces[t];
            a3 += A;
            auv += U;
        }
        EXPECT_NEAR(auv / a3, 1.0, 1e-9);
    }
    for (int s : seen) EXPECT_EQ(s, 1);
    EXPECT_EQ(r.stats.flippedOrDegenerate, 0u);
}

void print(const char* name, const ParameterizationResult& r) {
    const StretchStats& s = r.stats.stretch;
    std::printf("[ stretch  ] %s: %zu charts (planar %zu, lscm %zu, per-triangle %zu, splits %zu): L2 %.5f, Linf %.4f, "
                "angle mean %.5f max %.4f, area mean %.5f max %.4f\n",
                name, r.charts.size(), r.stats.planar, r.stats.lscm, r.stats.perTriangle, r.stats.splits, s.l2, s.linf,
                s.meanAngle, s.maxAngle, s.meanArea, s.maxArea);
}

TEST(MeshParameterize, SphereHasNoFlippedOrDegenerateTriangles) {
    const Scene scene = uvSphere(32, 16);
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    const ParameterizationResult r = parameterizeCharts(mesh, computeCharts(mesh));
    expectValid(mesh, r, 0.5);
    print("sphere 32x16", r);
    EXPECT_GT(r.stats.lscm, 0u);
    EXPECT_LT(r.stats.stretch.l2, 1.02);
    EXPECT_LT(r.stats.stretch.meanAngle, 1.02);
    EXPECT_LT(r.stats.stretch.maxArea, 1.2);
}

TEST(MeshParameterize, TorusHasNoFlippedOrDegenerateTriangles) {
    const Scene scene = torus(48, 24, 1.0, 0.3);
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    const ParameterizationResult r = parameterizeCharts(mesh, computeCharts(mesh));
    expectValid(mesh, r, 0.5);
    print("torus 48x24", r);
    EXPECT_LT(r.stats.stretch.l2, 1.02);
    EXPECT_LT(r.stats.stretch.meanAngle, 1.02);
    EXPECT_LT(r.stats.stretch.maxArea, 1.2);
}

TEST(MeshParameterize, BoxFacesAreExactPlanarProjections) {
    SceneBuilder b;
    const int m = b.addMaterial(glm::vec3(0.5f));
    b.addBox({-0.3, 0.1, 2.0}, {0.7, 0.6, 2.25}, m, false);
    b.addBox({0.0, 0.0, 0.0}, {5.0, 3.0, 4.0}, m, true);
    const Scene scene = b.build();
    std::size_t charts = 0;
    for (const MeshInstance& inst : scene.instances) {
        const ParameterizationResult r = parameterizeCharts(inst.mesh, computeCharts(inst.mesh));
        expectValid(inst.mesh, r, 0.999);
        for (const ParamChart& c : r.charts) {
            EXPECT_EQ(c.method, ParamMethod::Planar);
            EXPECT_EQ(c.faces.size(), 2u);  // the quad stays one chart
            EXPECT_NEAR(c.stretch.l2, 1.0, 1e-6);
            EXPECT_NEAR(c.stretch.linf, 1.0, 1e-6);
            EXPECT_NEAR(c.stretch.maxAngle, 1.0, 1e-6);
            EXPECT_NEAR(c.stretch.maxArea, 1.0, 1e-6);
            // Edge lengths are preserved exactly.
            for (const auto& t : c.triangles)
                for (int k = 0; k < 3; ++k) {
                    const int a = t[std::size_t(k)], d = t[std::size_t((k + 1) % 3)];
                    const auto pa = inst.mesh.point(SurfaceMesh::VertexHandle(c.vertices[std::size_t(a)]));
                    const auto pd = inst.mesh.point(SurfaceMesh::VertexHandle(c.vertices[std::size_t(d)]));
                    EXPECT_NEAR(glm::length(c.uv[std::size_t(a)] - c.uv[std::size_t(d)]), (pa - pd).norm(), 1e-9);
                }
        }
        charts += r.charts.size();
    }
    EXPECT_EQ(charts, 12u);  // 6 faces per box
}

TEST(MeshParameterize, LscmIsIsometricOnDevelopableStrip) {
    const Scene scene = cylinderStrip(120.0, 24, 6);
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    std::vector<std::int32_t> all(mesh.n_faces());
    for (std::size_t f = 0; f < all.size(); ++f) all[f] = std::int32_t(f);
    const ParameterizationResult r = parameterizeCharts(mesh, oneChart(mesh, all));
    expectValid(mesh, r, 0.99);
    ASSERT_EQ(r.charts.size(), 1u);
    EXPECT_EQ(r.charts[0].method, ParamMethod::Lscm);
    const StretchStats& s = r.charts[0].stretch;
    print("cylinder strip 120deg", r);
    EXPECT_NEAR(s.l2, 1.0, 1e-6);
    EXPECT_NEAR(s.linf, 1.0, 1e-6);
    EXPECT_NEAR(s.maxAngle, 1.0, 1e-6);  // angle distortion Γ/γ − 1 ≈ 0
    EXPECT_NEAR(s.maxArea, 1.0, 1e-6);
    // Unrolled: the bottom edge is as long as its polyline on the cylinder.
    const ParamChart& c = r.charts[0];
    auto uvOf = [&](int meshVertex) {
        for (std::size_t i = 0; i < c.vertices.size(); ++i)
            if (c.vertices[i] == meshVertex) return c.uv[i];
        return glm::dvec2(NAN);
    };
    const double chord = 2.0 * std::sin(120.0 * M_PI / 180.0 / 24 / 2);
    EXPECT_NEAR(glm::length(uvOf(24) - uvOf(0)), 24 * chord, 1e-6);
}

TEST(MeshParameterize, StretchMatchesSanderDefinition) {
    const Scene scene = singleMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    ChartWorkspace ws(mesh);
    const std::int32_t faces[1] = {0};
    ParamChart c = makeLocalChart(ws, faces);
    for (std::size_t i = 0; i < 3; ++i) {
        const auto p = mesh.point(SurfaceMesh::VertexHandle(c.vertices[i]));
        c.uv[i] = {2.0 * p[0], p[1]};  // u stretched ×2: Γ = 1 (along v), γ = 1/2 (along u)
    }
    const StretchStats s = measureStretch(mesh, c);
    EXPECT_NEAR(s.l2, std::sqrt((1.0 + 0.25) / 2.0), 1e-12);
    EXPECT_NEAR(s.linf, 1.0, 1e-12);
    EXPECT_NEAR(s.meanAngle, 2.0, 1e-12);
    EXPECT_NEAR(s.meanArea, 2.0, 1e-12);
    EXPECT_NEAR(s.areaM2, 0.5, 1e-12);
    // Mirrored UVs are flipped triangles.
    for (auto& uv : c.uv) uv.x = -uv.x;
    EXPECT_EQ(countBadTriangles(mesh, c, 1e-3), 1u);
}

TEST(MeshParameterize, FailedLscmIsSplitUntilValid) {
    // A sphere without its south cap is a disk, but flattening it in one piece is hopeless: the conformal map
    // shrinks the far side to nothing. The result must still have no flipped or degenerate triangles.
    const Scene scene = uvSphere(32, 16);
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    std::vector<std::int32_t> faces;
    for (std::size_t f = 0; f + 32 < mesh.n_faces(); ++f) faces.push_back(std::int32_t(f));
    const ParameterizationResult r = parameterizeCharts(mesh, oneChart(mesh, faces));
    print("sphere minus cap as one chart", r);
    EXPECT_GE(r.stats.failedLscm, 1u);
    EXPECT_GE(r.stats.splits, 1u);
    EXPECT_GT(r.charts.size(), 1u);
    std::size_t covered = 0;
    for (const auto& c : r.charts) covered += c.faces.size();
    EXPECT_EQ(covered, faces.size());
    // Faces outside the chart are not parameterized; check the rest.
    for (const ParamChart& c : r.charts)
        for (std::size_t t = 0; t < c.faces.size(); ++t) EXPECT_GT(areaUv(c, t), 1e-3 * area3d(mesh, c, t));
    EXPECT_EQ(r.stats.flippedOrDegenerate, 0u);

    // With no splitting allowed the last resort is per-triangle projection: still valid.
    ParameterizeSettings noSplit;
    noSplit.maxSplitDepth = 0;
    const ParameterizationResult pt = parameterizeCharts(mesh, oneChart(mesh, faces), noSplit);
    EXPECT_EQ(pt.charts.size(), faces.size());
    EXPECT_EQ(pt.stats.perTriangle, faces.size());
    EXPECT_EQ(pt.stats.flippedOrDegenerate, 0u);
    EXPECT_NEAR(pt.stats.stretch.linf, 1.0, 1e-9);
}

TEST(MeshParameterize, BoundaryOverlapIsDetected) {
    // A straight strip of 12 quads laid out in UV as a C-shaped ring: no triangle flips, but once the ring
    // turns more than 360° its ends overlap, which only the boundary test sees.
    const int n = 12;
    std::vector<glm::dvec3> p;
    for (int i = 0; i <= n; ++i) p.push_back({double(i), 0.0, 0.0});  // bottom row: vertex i
    for (int i = 0; i <= n; ++i) p.push_back({double(i), 1.0, 0.0});  // top row: vertex n+1+i
    std::vector<Tri> t;
    for (int i = 0; i < n; ++i) {
        t.push_back({i, i + 1, n + 2 + i});
        t.push_back({i, n + 2 + i, n + 1 + i});
    }
    const Scene scene = singleMesh(p, t);
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    ChartWorkspace ws(mesh);
    std::vector<std::int32_t> faces(mesh.n_faces());
    for (std::size_t f = 0; f < faces.size(); ++f) faces[f] = std::int32_t(f);
    ParamChart c = makeLocalChart(ws, faces);
    auto layRing = [&](double degrees) {
        for (std::size_t k = 0; k < c.vertices.size(); ++k) {
            const int v = c.vertices[k];
            const bool bottom = v <= n;
            const double a = degrees * M_PI / 180.0 * (bottom ? v : v - n - 1) / n;
            const double r = bottom ? 1.5 : 1.0;  // the bottom row goes outside: counter-clockwise stays positive
            c.uv[k] = {r * std::cos(a), r * std::sin(a)};
        }
    };
    layRing(300.0);
    EXPECT_EQ(countBadTriangles(mesh, c, 1e-3), 0u);
    EXPECT_FALSE(boundaryOverlaps(c));
    layRing(420.0);
    EXPECT_EQ(countBadTriangles(mesh, c, 1e-3), 0u);
    EXPECT_TRUE(boundaryOverlaps(c));
}

}  // namespace
}  // namespace hemibake
