// Chart segmentation: every face in exactly one chart, curved charts are disks, planar faces become planar
// charts, creases / materials separate charts, non-indexed meshes are welded before segmentation.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "mesh/charts.h"
#include "mesh/scene_builder.h"
#include "mesh/uv_atlas.h"
#include "support/test_meshes.h"

namespace hemibake {
namespace {

using test::Tri;
using test::singleMesh;
using test::torus;
using test::uvSphere;

// A closed box as one mesh with 8 shared corners, outward facing.
Scene closedBox() {
    std::vector<glm::dvec3> p;
    for (int i = 0; i < 8; ++i) p.push_back({i & 1 ? 2.0 : 0.0, i & 2 ? 1.0 : 0.0, i & 4 ? 0.5 : 0.0});
    const int q[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    std::vector<Tri> t;
    for (const auto& f : q) {
        t.push_back({f[0], f[1], f[2]});
        t.push_back({f[0], f[2], f[3]});
    }
    return singleMesh(p, t);
}

// An open tube (cylinder without caps), outward facing.
Scene tube(int nu, int nh) {
    std::vector<glm::dvec3> p;
    for (int j = 0; j <= nh; ++j)
        for (int i = 0; i < nu; ++i) {
            const double a = 2 * M_PI * i / nu;
            p.push_back({std::cos(a), double(j) / nh, -std::sin(a)});
        }
    auto id = [&](int j, int i) { return j * nu + (i % nu); };
    std::vector<Tri> t;
    for (int j = 0; j < nh; ++j)
        for (int i = 0; i < nu; ++i) {
            t.push_back({id(j, i), id(j, i + 1), id(j + 1, i + 1)});
            t.push_back({id(j, i), id(j + 1, i + 1), id(j + 1, i)});
        }
    return singleMesh(p, t);
}

// Checks that the ChartSet arrays are consistent and every face is in exactly one chart.
void expectPartition(const SurfaceMesh& mesh, const ChartSet& cs) {
    ASSERT_EQ(cs.faceChart.size(), mesh.n_faces());
    ASSERT_EQ(cs.chartFaceStart.size(), cs.size() + 1);
    ASSERT_EQ(cs.chartFaces.size(), mesh.n_faces());
    std::vector<int> seen(mesh.n_faces(), 0);
    for (std::size_t c = 0; c < cs.size(); ++c) {
        EXPECT_FALSE(cs.faces(c).empty());
        for (int f : cs.faces(c)) {
            ++seen[std::size_t(f)];
            EXPECT_EQ(cs.faceChart[std::size_t(f)], int(c));
        }
    }
    for (int s : seen) EXPECT_EQ(s, 1);
}

TEST(MeshCharts, ClosedBoxGivesSixPlanarDiskCharts) {
    const Scene scene = closedBox();
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    const ChartSet cs = computeCharts(mesh);
    expectPartition(mesh, cs);
    ASSERT_EQ(cs.size(), 6u);
    ChartWorkspace ws(mesh);
    std::set<std::tuple<int, int, int>> normals;
    for (std::size_t c = 0; c < cs.size(); ++c) {
        EXPECT_TRUE(cs.planar[c]);
        EXPECT_EQ(cs.faces(c).size(), 2u);
        EXPECT_TRUE(chartTopology(ws, cs.faces(c)).isDisk());
        const glm::dvec3 n = cs.normal[c];
        normals.insert({int(std::lround(n.x)), int(std::lround(n.y)), int(std::lround(n.z))});
        EXPECT_NEAR(std::abs(n.x) + std::abs(n.y) + std::abs(n.z), 1.0, 1e-12);
    }
    EXPECT_EQ(normals.size(), 6u);  // one chart per side
}

TEST(MeshCharts, SphereChartsAreDisksWithBoundedNormalDeviation) {
    const Scene scene = uvSphere(32, 16);
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    const ChartSet cs = computeCharts(mesh);
    expectPartition(mesh, cs);
    EXPECT_GT(cs.size(), 6u);  // a sphere cannot be one chart under a 18° normal cone
    EXPECT_LT(cs.size(), 200u);
    ChartWorkspace ws(mesh);
    double worst = 1.0;
    for (std::size_t c = 0; c < cs.size(); ++c) {
        EXPECT_TRUE(chartTopology(ws, cs.faces(c)).isDisk()) << "chart " << c;
        for (int f : cs.faces(c)) worst = std::min(worst, glm::dot(ws.geometry.normal[std::size_t(f)], cs.normal[c]));
    }
    // Faces joined within cos 0.95 of the running mean (merged leftovers within 0.85 of the merged mean).
    EXPECT_GT(worst, 0.85);
    // Leftover slivers of the growth were merged into their neighbours.
    EXPECT_GT(cs.mergedCharts, 0u);
    std::size_t smallest = mesh.n_faces();
    for (std::size_t c = 0; c < cs.size(); ++c) smallest = std::min(smallest, cs.faces(c).size());
    EXPECT_GE(smallest, 4u);
    ChartSettings noMerge;
    noMerge.mergeSmallCharts = false;
    EXPECT_GT(computeCharts(mesh, noMerge).size(), cs.size());
}

TEST(MeshCharts, TubeGrownAsOneChartIsSplitIntoDisks) {
    const Scene scene = tube(24, 4);
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    ChartSettings s;
    s.maxNormalDeviationCos = -1.0;  // let everything join: the grown chart is an annulus
    s.creaseAngleDegrees = 180.0;
    s.maxCost = 100.0;
    const ChartSet cs = computeCharts(mesh, s);
    expectPartition(mesh, cs);
    EXPECT_GE(cs.size(), 2u);
    EXPECT_GE(cs.nonDiskSplits, 1u);
    ChartWorkspace ws(mesh);
    EXPECT_FALSE(chartTopology(ws, cs.chartFaces).isDisk());  // the whole tube: 2 boundary loops
    EXPECT_EQ(chartTopology(ws, cs.chartFaces).boundaryLoops, 2);
    for (std::size_t c = 0; c < cs.size(); ++c) EXPECT_TRUE(chartTopology(ws, cs.faces(c)).isDisk()) << "chart " << c;
}

TEST(MeshCharts, ClosedTorusForcedIntoOneChartIsSplitIntoDisks) {
    const Scene scene = torus(24, 12, 1.0, 0.3);
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    ChartSettings s;
    s.maxNormalDeviationCos = -1.0;
    s.creaseAngleDegrees = 180.0;
    s.maxCost = 100.0;
    const ChartSet cs = computeCharts(mesh, s);
    expectPartition(mesh, cs);
    EXPECT_GE(cs.nonDiskSplits, 1u);
    ChartWorkspace ws(mesh);
    const ChartTopology whole = chartTopology(ws, cs.chartFaces);
    EXPECT_EQ(whole.boundaryLoops, 0);
    EXPECT_EQ(whole.euler(), 0);  // torus
    for (std::size_t c = 0; c < cs.size(); ++c) EXPECT_TRUE(chartTopology(ws, cs.faces(c)).isDisk()) << "chart " << c;
}

// A flat square frame: outer 3×3, inner hole 1×1 (8 triangles).
Scene squareFrame() {
    const std::vector<glm::dvec3> p{{0, 0, 0}, {3, 0, 0}, {3, 3, 0}, {0, 3, 0}, {1, 1, 0}, {2, 1, 0}, {2, 2, 0}, {1, 2, 0}};
    const std::vector<Tri> t{{0, 1, 5}, {0, 5, 4}, {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
    return singleMesh(p, t);
}

TEST(MeshCharts, PlanarChartWithHoleIsKeptOrSplitOnRequest) {
    const Scene scene = squareFrame();
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    ChartWorkspace ws(mesh);
    const ChartSet kept = computeCharts(mesh);
    expectPartition(mesh, kept);
    ASSERT_EQ(kept.size(), 1u);
    EXPECT_TRUE(kept.planar[0]);
    EXPECT_EQ(kept.planarWithHoles, 1u);
    EXPECT_EQ(chartTopology(ws, kept.faces(0)).boundaryLoops, 2);

    ChartSettings s;
    s.allowPlanarHoles = false;
    const ChartSet split = computeCharts(mesh, s);
    expectPartition(mesh, split);
    EXPECT_GE(split.size(), 2u);
    for (std::size_t c = 0; c < split.size(); ++c) {
        EXPECT_TRUE(chartTopology(ws, split.faces(c)).isDisk());
        EXPECT_TRUE(split.planar[c]);
    }
}

TEST(MeshCharts, MaterialBoundariesAndCreasesSeparateCharts) {
    // A flat 4×2 grid of quads; the right half gets another material.
    std::vector<glm::dvec3> p;
    for (int j = 0; j <= 2; ++j)
        for (int i = 0; i <= 4; ++i) p.push_back({double(i), double(j), 0.0});
    std::vector<Tri> t;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 4; ++i) {
            const int a = j * 5 + i;
            t.push_back({a, a + 1, a + 6});
            t.push_back({a, a + 6, a + 5});
        }
    Scene scene = singleMesh(p, t);
    SurfaceMesh& mesh = scene.instances[0].mesh;
    for (auto f : mesh.faces()) {
        const auto c = mesh.calc_face_centroid(f);
        mesh.material(f) = c[0] > 2.0 ? 1 : 0;
    }
    const ChartSet cs = computeCharts(mesh);
    expectPartition(mesh, cs);
    ASSERT_EQ(cs.size(), 2u);
    for (std::size_t c = 0; c < cs.size(); ++c) {
        std::set<int> mats;
        for (int f : cs.faces(c)) mats.insert(mesh.material(SurfaceMesh::FaceHandle(f)));
        EXPECT_EQ(mats.size(), 1u);
    }
    ChartSettings noMaterials;
    noMaterials.splitAtMaterials = false;
    EXPECT_EQ(computeCharts(mesh, noMaterials).size(), 1u);

    // Two quads meeting at a 60° fold: a crease at 45° separates them even when the normal cone allows both.
    const Scene fold = singleMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1 + std::cos(M_PI / 3), 0, std::sin(M_PI / 3)},
                                   {1 + std::cos(M_PI / 3), 1, std::sin(M_PI / 3)}},
                                  {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}});
    ChartSettings wide;
    wide.maxNormalDeviationCos = -1.0;
    wide.creaseAngleDegrees = 45.0;
    EXPECT_EQ(computeCharts(fold.instances[0].mesh, wide).size(), 2u);
    wide.creaseAngleDegrees = 90.0;
    EXPECT_EQ(computeCharts(fold.instances[0].mesh, wide).size(), 1u);
}

TEST(MeshCharts, NonIndexedTrianglesAreWeldedIntoOneChart) {
    // A quad as two triangles that share no vertices (non-indexed glTF).
    const Scene scene = singleMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2}, {3, 4, 5}});
    const SurfaceMesh& mesh = scene.instances[0].mesh;
    EXPECT_EQ(computeCharts(mesh).size(), 2u);  // as loaded: two components
    const auto welded = weldCoincidentVertices(mesh);
    ASSERT_TRUE(welded.has_value());
    EXPECT_EQ(welded->mergedVertices, 2u);
    EXPECT_EQ(welded->mesh.n_vertices(), 4u);
    EXPECT_EQ(welded->mesh.n_faces(), 2u);
    EXPECT_EQ(computeCharts(welded->mesh).size(), 1u);
    // Corner sources point at input vertices with the same positions.
    for (std::size_t f = 0; f < 2; ++f) {
        const auto wc = faceCorners(welded->mesh, int(f));
        for (std::size_t k = 0; k < 3; ++k) {
            const auto a = welded->mesh.point(SurfaceMesh::VertexHandle(wc[k]));
            const auto b = mesh.point(SurfaceMesh::VertexHandle(welded->cornerSource[3 * f + k]));
            EXPECT_EQ(a, b);
        }
    }
    EXPECT_FALSE(weldCoincidentVertices(closedBox().instances[0].mesh).has_value());

    // Through unwrapScene: one chart, six unwrapped vertices, coincident ones with equal UVs.
    const UvAtlas atlas = unwrapScene(scene, {});
    ASSERT_EQ(atlas.charts.size(), 1u);
    const UnwrappedInstance& ui = atlas.instances[0];
    ASSERT_EQ(ui.uv.size(), 6u);
    for (std::size_t a = 0; a < 6; ++a)
        for (std::size_t b = 0; b < 6; ++b) {
            const auto pa = mesh.point(SurfaceMesh::VertexHandle(ui.vertexSource[a]));
            const auto pb = mesh.point(SurfaceMesh::VertexHandle(ui.vertexSource[b]));
            if (pa == pb) {
                EXPECT_EQ(ui.uv[a], ui.uv[b]);
            }
        }
}

}  // namespace
}  // namespace hemibake
