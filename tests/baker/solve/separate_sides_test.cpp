// Issue 15: no element, patch or texel takes light on one side of a wall standing in a slab and gives it to the
// other side.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "baker/rays/embree_scene.h"
#include "baker/solve/separate_sides.h"
#include "mesh/scene_builder.h"
#include "mesh/subdivision.h"

namespace hemibake {
namespace {

// A box standing across the middle of a floor slab; the slab's top is one quad.
Scene floorUnderAWall() {
    SceneBuilder b("floor under a wall");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    b.addBox({0, -0.2, 0}, {4, 0, 4}, grey, false, "slab");
    b.addBox({1.4, -0.05, 0}, {1.6, 2, 4}, grey, false, "wall");  // across the middle of 1 m elements
    return b.build();
}

}  // namespace

TEST(SeparateSides, ElementsUnderAWallStraddleUntilBisected) {
    const Scene scene = floorUnderAWall();
    const EmbreeScene rays(scene);
    const SubdivisionSettings sizes{2.0, 1.0, 0.0};
    SideSeparationSettings s;
    s.enabled = true;
    const PatchMesh coarse = subdivide(scene, sizes);
    std::size_t straddling = 0;
    for (std::size_t e = 0; e < coarse.elements.size(); ++e) straddling += elementStraddles(rays, coarse, e, s);
    EXPECT_GT(straddling, 0u);  // the slab's 1 m elements lie on both sides of the wall

    SideSeparationReport report;
    const PatchMesh apart = subdivideApart(scene, rays, sizes, nullptr, s, &report);
    std::printf("straddling before %zu of %zu elements; after %d levels %zu elements, %zu left, %zu patches split (+%zu)\n",
                straddling, coarse.elements.size(), report.levels, apart.elements.size(), report.straddlingElementsLeft,
                report.patchesSplit, report.patchesAdded);
    EXPECT_EQ(report.straddlingElementsLeft, 0u);
    for (std::size_t e = 0; e < apart.elements.size(); ++e) ASSERT_FALSE(elementStraddles(rays, apart, e, s)) << e;
    // Only the band along the wall is refined (a uniform 1/64 subdivision would be 4096× the coarse count).
    EXPECT_LT(apart.elements.size(), 20 * coarse.elements.size());
    // No patch holds exposed elements on both sides of the wall (x < 1.4 and x > 1.6).
    const std::size_t slab = 0;
    for (std::size_t p = 0; p < apart.patches.size(); ++p) {
        bool west = false, east = false;
        for (std::uint32_t e = apart.patches.firstElement[p]; e < apart.patches.firstElement[p] + apart.patches.elementCount[p]; ++e) {
            if (apart.elements.instance[e] != slab || apart.elements.normal[e].y < 0.5f) continue;
            west = west || apart.elements.centroid[e].x < 1.4;
            east = east || apart.elements.centroid[e].x > 1.6;
        }
        EXPECT_FALSE(west && east) << "patch " << p;
    }
    // The element arrays stay consistent: each patch's run names it, areas add up.
    double area = 0.0, patchArea = 0.0;
    for (std::size_t p = 0; p < apart.patches.size(); ++p) {
        patchArea += apart.patches.areaM2[p];
        for (std::uint32_t e = apart.patches.firstElement[p]; e < apart.patches.firstElement[p] + apart.patches.elementCount[p]; ++e)
            ASSERT_EQ(apart.elements.patch[e], p);
    }
    for (double a : apart.elements.areaM2) area += a;
    EXPECT_NEAR(patchArea, area, 1e-9 * area);
    double coarseArea = 0.0;
    for (double a : coarse.elements.areaM2) coarseArea += a;
    EXPECT_NEAR(area, coarseArea, 1e-9 * area);
}

TEST(SeparateSides, OffIsExactlySubdivide) {
    const Scene scene = floorUnderAWall();
    const EmbreeScene rays(scene);
    SideSeparationSettings s;
    s.enabled = false;
    const PatchMesh a = subdivide(scene, {2.0, 1.0, 0.0});
    const PatchMesh b = subdivideApart(scene, rays, {2.0, 1.0, 0.0}, nullptr, s);
    ASSERT_EQ(a.elements.size(), b.elements.size());
    ASSERT_EQ(a.patches.size(), b.patches.size());
    for (std::size_t e = 0; e < a.elements.size(); ++e) ASSERT_EQ(a.elements.centroid[e], b.elements.centroid[e]);
}

}  // namespace hemibake
