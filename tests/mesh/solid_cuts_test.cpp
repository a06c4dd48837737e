// Faces cut along the solids that cross them (mesh/solid_cuts.h): what is buried goes, what is exposed stays with
// its area exact, and no piece (nor any element bisected from it) lies on both sides of a wall standing in a slab.
#include <gtest/gtest.h>

#include "mesh/gltf_loader.h"
#include "mesh/scene_builder.h"
#include "mesh/solid_cuts.h"
#include "mesh/subdivision.h"
#include "support/test_meshes.h"

using namespace hemibake;
using hemibake::test::addSolidBox;

namespace {

double area(const SurfaceMesh& m) {
    double a = 0.0;
    for (auto f : m.faces()) a += m.faceArea(f);
    return a;
}

// Area of the faces of `m` whose normal is close to `n` and that lie in the plane n·x = offset.
double areaInPlane(const SurfaceMesh& m, const glm::dvec3& n, double offset) {
    double a = 0.0;
    for (auto f : m.faces()) {
        const auto fn = m.normal(f);
        const auto p = m.point(*m.cfv_iter(f));
        if (fn[0] * n.x + fn[1] * n.y + fn[2] * n.z > 0.999 && std::abs(p[0] * n.x + p[1] * n.y + p[2] * n.z - offset) < 1e-9)
            a += m.faceArea(f);
    }
    return a;
}

double tolerance(const Scene& s) { return 1e-7 * s.bounds().diagonal(); }

// A face's extent in x and z.
struct FaceExtent {
    double lo = 1e9, hi = -1e9, loZ = 1e9, hiZ = -1e9;
};
FaceExtent extentXZ(const SurfaceMesh& m, SurfaceMesh::FaceHandle f) {
    FaceExtent e;
    for (auto v : m.fv_range(f)) {
        e.lo = std::min(e.lo, m.point(v)[0]);
        e.hi = std::max(e.hi, m.point(v)[0]);
        e.loZ = std::min(e.loZ, m.point(v)[2]);
        e.hiZ = std::max(e.hiZ, m.point(v)[2]);
    }
    return e;
}

}  // namespace

TEST(SolidCuts, WallThroughASlabSplitsItsTopAndDropsTheBuriedStrip) {
    SceneBuilder b("slab and wall");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    addSolidBox(b, {-0.2, -0.2, -0.2}, {4.4, 0.0, 3.2}, grey, "slab");
    addSolidBox(b, {2.0, -0.05, 0.3}, {2.2, 2.55, 2.7}, grey, "wall");
    const Scene scene = b.build();
    const SolidSet solids(scene, tolerance(scene));
    ASSERT_EQ(solids.size(), 2u);

    SolidCutStats stats;
    const SurfaceMesh slab = cutAlongSolids(scene.instances[0].mesh, 0, solids, false, 0.0, &stats);
    // The top loses exactly the wall's footprint; nothing else of the slab is inside the wall.
    EXPECT_NEAR(areaInPlane(slab, {0, 1, 0}, 0.0), 4.6 * 3.4 - 0.2 * 2.4, 1e-9);
    EXPECT_NEAR(area(scene.instances[0].mesh) - area(slab), 0.2 * 2.4, 1e-9);
    EXPECT_NEAR(stats.areaDroppedM2, 0.2 * 2.4, 1e-9);
    EXPECT_GT(stats.facesCut, 0u);
    // No piece of the top lies on both sides of the wall, or under it.
    for (auto f : slab.faces()) {
        if (slab.normal(f)[1] < 0.999) continue;
        const auto [lo, hi, loZ, hiZ] = extentXZ(slab, f);
        const bool beside = hi <= 2.0 + 1e-9 || lo >= 2.2 - 1e-9 || hiZ <= 0.3 + 1e-9 || loZ >= 2.7 - 1e-9;
        EXPECT_TRUE(beside) << "x " << lo << ".." << hi << " z " << loZ << ".." << hiZ;
    }

    // The wall loses its bottom and the 5 cm of its sides inside the slab.
    const SurfaceMesh wall = cutAlongSolids(scene.instances[1].mesh, 1, solids, false, 0.0, &stats);
    const double buried = 0.2 * 2.4 + 0.05 * (2 * 0.2 + 2 * 2.4);
    EXPECT_NEAR(area(scene.instances[1].mesh) - area(wall), buried, 1e-9);
    EXPECT_NEAR(areaInPlane(wall, {0, -1, 0}, 0.05), 0.0, 1e-12);
}

TEST(SolidCuts, ElementsNeverStraddleTheWall) {
    SceneBuilder b("slab and wall");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    addSolidBox(b, {-0.2, -0.2, -0.2}, {4.4, 0.0, 3.2}, grey, "slab");
    addSolidBox(b, {2.0, -0.05, -0.2}, {2.05, 2.55, 3.2}, grey, "thin wall");  // 5 cm, the slab's full depth
    const Scene scene = b.build();
    SubdivisionSettings s;
    s.patchSizeM = 6.0;    // coarse, as the presets make them on a 50 m level: a patch is a whole slab triangle
    s.elementSizeM = 1.6;
    for (bool cut : {false, true}) {
        s.cutAlongSolids = cut;
        const PatchMesh pm = subdivide(scene, s);
        std::size_t straddling = 0;
        for (std::size_t e = 0; e < pm.elements.size(); ++e) {
            if (pm.elements.normal[e].y < 0.999f || std::abs(pm.elements.centroid[e].y) > 1e-9) continue;
            double lo = 1e9, hi = -1e9;
            for (std::uint32_t v : pm.elements.triangles[e]) {
                lo = std::min(lo, pm.elements.vertices[v].x);
                hi = std::max(hi, pm.elements.vertices[v].x);
            }
            straddling += lo < 2.0 - 1e-9 && hi > 2.05 + 1e-9;
        }
        // Patches: all elements of one patch on one side of the wall.
        std::size_t straddlingPatches = 0;
        for (std::size_t p = 0; p < pm.patches.size(); ++p) {
            bool west = false, east = false;
            for (std::uint32_t e = pm.patches.firstElement[p]; e < pm.patches.firstElement[p] + pm.patches.elementCount[p]; ++e) {
                if (pm.elements.normal[e].y < 0.999f || std::abs(pm.elements.centroid[e].y) > 1e-9) continue;
                west |= pm.elements.centroid[e].x < 2.0;
                east |= pm.elements.centroid[e].x > 2.05;
            }
            straddlingPatches += west && east;
        }
        if (cut) {
            EXPECT_EQ(straddling, 0u);
            EXPECT_EQ(straddlingPatches, 0u);
            EXPECT_EQ(pm.solidCuts.solids, 2u);
        } else {
            EXPECT_GT(straddling, 0u);  // the check can fail: without cuts the slab's elements run under the wall
            EXPECT_GT(straddlingPatches, 0u);
        }
    }
}

TEST(SolidCuts, ContactCoversBothFacesAndCoplanarFacesLookingTheSameWayStay) {
    SceneBuilder b("contact");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    addSolidBox(b, {0, -0.3, 0}, {4, 0, 4}, grey, "slab");
    addSolidBox(b, {1, 0, 1}, {2, 1, 2}, grey, "block on the slab");
    addSolidBox(b, {3, -0.5, 3}, {5, 0, 5}, grey, "second slab, same top");
    const Scene scene = b.build();
    const SolidSet solids(scene, tolerance(scene));
    ASSERT_EQ(solids.size(), 3u);
    const SurfaceMesh slab = cutAlongSolids(scene.instances[0].mesh, 0, solids, false);
    const SurfaceMesh block = cutAlongSolids(scene.instances[1].mesh, 1, solids, false);
    const SurfaceMesh second = cutAlongSolids(scene.instances[2].mesh, 2, solids, false);
    EXPECT_NEAR(areaInPlane(slab, {0, 1, 0}, 0.0), 16.0 - 1.0, 1e-9);  // under the block: covered
    EXPECT_NEAR(areaInPlane(block, {0, -1, 0}, 0.0), 0.0, 1e-12);       // the block's bottom: covered
    EXPECT_NEAR(areaInPlane(block, {0, 1, 0}, 1.0), 1.0, 1e-9);
    EXPECT_NEAR(areaInPlane(second, {0, 1, 0}, 0.0), 4.0, 1e-9);  // coplanar tops, both kept
    // Where the second slab overlaps the first (x, z in 3..4), the first's bottom and side faces are inside it.
    EXPECT_NEAR(area(scene.instances[0].mesh) - area(slab), 1.0 + 1.0 + 2 * 0.3, 1e-9);
}

TEST(SolidCuts, OpenSurfacesAreNotSolidsAndCutNothing) {
    SceneBuilder b("open");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    addSolidBox(b, {0, -0.3, 0}, {4, 0, 4}, grey, "slab");
    addSolidBox(b, {1, -0.1, 1}, {2, 1, 2}, grey, "box without a top", false);
    const Scene scene = b.build();
    const SolidSet solids(scene, tolerance(scene));
    EXPECT_EQ(solids.size(), 1u);
    const SurfaceMesh slab = cutAlongSolids(scene.instances[0].mesh, 0, solids, false);
    EXPECT_NEAR(area(slab), area(scene.instances[0].mesh), 1e-12);
}

TEST(SolidCuts, GeneratedLevelKeepsNoAreaInsideASolid) {
    const Scene scene = loadGltf(std::string(HEMIBAKE_SOURCE_DIR) + "/examples/level_small.gltf");
    const SolidSet solids(scene, tolerance(scene));
    EXPECT_GT(solids.size(), 100u);  // walls with openings, slabs, pillars, props: the generator's closed solids
    SolidCutStats stats;
    double insideM2 = 0.0, keptM2 = 0.0;
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const SurfaceMesh cut = cutAlongSolids(scene.instances[i].mesh, i, solids, false, 0.0, &stats);
        for (auto f : cut.faces()) {
            keptM2 += cut.faceArea(f);
            OpenMesh::Vec3d c(0.0);
            for (auto v : cut.fv_range(f)) c += cut.point(v) / 3.0;
            const auto n = cut.normal(f);
            const glm::dvec3 q = glm::dvec3(c[0], c[1], c[2]) + 1e-4 * glm::dvec3(n[0], n[1], n[2]);
            for (std::size_t s = 0; s < solids.size(); ++s) {
                const auto& solid = solids.solids()[s];
                if (solid.instance == i) continue;
                if (glm::any(glm::lessThan(q, solid.lo)) || glm::any(glm::greaterThan(q, solid.hi))) continue;
                if (solids.windingNumber(s, q) > 0.5) insideM2 += cut.faceArea(f);
            }
        }
    }
    EXPECT_GT(stats.facesCut, 100u);
    EXPECT_GT(stats.areaDroppedM2, 1.0);
    // Slivers a few micrometres wide where two solids' faces nearly coincide can be classified either way.
    EXPECT_LT(insideM2, 1e-6 * keptM2) << "of " << keptM2 << " m²";
}

// A panel hanging 5 cm under a ceiling slab: within the gap distance its outline is cut into the ceiling's
// underside (nothing dropped, the area exact, no piece both over the gap and beside it); beyond it nothing is cut.
TEST(SolidCuts, PanelUnderACeilingCutsItsOutlineIntoTheCeiling) {
    SceneBuilder b("panel under a ceiling");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    addSolidBox(b, {-0.2, 3.0, -0.2}, {4.2, 3.2, 4.2}, grey, "ceiling slab");
    addSolidBox(b, {1.4, 2.9, 1.7}, {2.6, 2.95, 2.3}, grey, "panel");
    const Scene scene = b.build();
    const SolidSet solids(scene, tolerance(scene));
    ASSERT_EQ(solids.size(), 2u);

    SolidCutStats stats;
    const SurfaceMesh ceiling = cutAlongSolids(scene.instances[0].mesh, 0, solids, false, 0.1, &stats);
    EXPECT_GT(stats.facesCutAtGaps, 0u);
    EXPECT_EQ(stats.facesDropped, 0u);
    EXPECT_EQ(stats.piecesDropped, 0u);
    EXPECT_NEAR(area(ceiling), area(scene.instances[0].mesh), 1e-9);
    double overGapM2 = 0.0;
    for (auto f : ceiling.faces()) {
        if (ceiling.normal(f)[1] > -0.999) continue;
        const auto [lo, hi, loZ, hiZ] = extentXZ(ceiling, f);
        const bool over = lo >= 1.4 - 1e-9 && hi <= 2.6 + 1e-9 && loZ >= 1.7 - 1e-9 && hiZ <= 2.3 + 1e-9;
        const bool beside = hi <= 1.4 + 1e-9 || lo >= 2.6 - 1e-9 || hiZ <= 1.7 + 1e-9 || loZ >= 2.3 - 1e-9;
        EXPECT_TRUE(over || beside) << "x " << lo << ".." << hi << " z " << loZ << ".." << hiZ;
        if (over) overGapM2 += ceiling.faceArea(f);
    }
    EXPECT_NEAR(overGapM2, 1.2 * 0.6, 1e-9);  // the panel's footprint, exactly

    // A gap distance under 5 cm: the panel is too far to cut anything.
    SolidCutStats far;
    const SurfaceMesh uncut = cutAlongSolids(scene.instances[0].mesh, 0, solids, false, 0.04, &far);
    EXPECT_EQ(far.facesCutAtGaps, 0u);
    EXPECT_EQ(uncut.n_faces(), scene.instances[0].mesh.n_faces());
}
