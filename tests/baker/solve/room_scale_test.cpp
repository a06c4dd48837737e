// Issue 14: element sizes follow the rooms, not the scene's diagonal. A closed 4 × 3 × 5 m room beside a 60 m
// ground plane open to the sky: the room's elements come down to a third of its mean free path, the ground keeps
// the diagonal's size. The mean free path of a closed convex room is 4V/S (Cauchy: the mean cosine-weighted
// chord), here 240/94 = 2.553 m.
#include <gtest/gtest.h>

#include "baker/rays/embree_scene.h"
#include "baker/solve/room_scale.h"
#include "mesh/scene_builder.h"
#include "mesh/triangle_sampling.h"

using namespace hemibake;

namespace {

Scene roomBesideAGround() {
    SceneBuilder b("room and ground");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    b.addBox({0, 0, 0}, {4, 3, 5}, grey, true, "room");
    b.addQuad({-30, -1, -30}, {-30, -1, 30}, {30, -1, 30}, {30, -1, -30}, grey, "ground");  // faces up, open
    return b.build();
}

SolveSettings settingsWithRoomFraction(double fraction) {
    SolveSettings s;
    s.subdivision.patchSizeM = 4.0;
    s.subdivision.elementSizeM = 2.0;
    s.roomScale.roomFraction = fraction;
    return s;
}

}  // namespace

TEST(RoomScale, RoomElementsFollowTheMeanFreePathAndOpenGroundKeepsItsSize) {
    const Scene scene = roomBesideAGround();
    const EmbreeScene rays(scene);
    const SolveSettings settings = settingsWithRoomFraction(1.0 / 3.0);
    RoomScaleReport report;
    const RefinementRequest request = findRoomScaleRegions(scene, rays, settings, &report);
    const double fourVOverS = 4.0 * 60.0 / 94.0;
    std::printf("regions %zu, smallest %.3f m, median free path %.3f m (4V/S %.3f m)\n", report.regions,
                report.smallestSizeM, report.medianFreePathM, fourVOverS);
    // The room's elements are most of the measured area; 16 rays per element, corners nearer: within 15 %.
    EXPECT_NEAR(report.medianFreePathM, fourVOverS, 0.15 * fourVOverS);
    EXPECT_GT(report.regions, 0u);
    EXPECT_GE(report.smallestSizeM, settings.subdivision.elementSizeM * settings.roomScale.minSizeFraction);

    const PatchMesh refined = subdivide(scene, settings.subdivision, &request);
    const PatchMesh preset = subdivide(scene, settings.subdivision);
    const std::uint32_t ground = std::uint32_t(scene.instances.size() - 1);  // the box is six quads, then the ground
    double roomLongest = 0.0, groundLongest = 0.0, presetGround = 0.0;
    for (std::size_t e = 0; e < refined.elements.size(); ++e) {
        const double edge = longestEdgeM(refined.elements, e);
        double& longest = refined.elements.instance[e] == ground ? groundLongest : roomLongest;
        longest = std::max(longest, edge);
    }
    for (std::size_t e = 0; e < preset.elements.size(); ++e)
        if (preset.elements.instance[e] == ground) presetGround = std::max(presetGround, longestEdgeM(preset.elements, e));
    // Every room element is at most a third of the room's free path where it stands (≤ 1/3 of the farthest
    // corner-to-corner chord, in practice under 1.1 m); the open ground is exactly as the diagonal made it.
    EXPECT_LT(roomLongest, 1.1) << "room elements";
    EXPECT_LT(roomLongest, 0.6 * settings.subdivision.elementSizeM);
    EXPECT_DOUBLE_EQ(groundLongest, presetGround);
    EXPECT_GT(refined.elements.size(), preset.elements.size());
}

TEST(RoomScale, OffLeavesTheSubdivisionAlone) {
    const Scene scene = roomBesideAGround();
    const EmbreeScene rays(scene);
    RoomScaleReport report;
    EXPECT_TRUE(findRoomScaleRegions(scene, rays, settingsWithRoomFraction(0.0), &report).regions.empty());
    EXPECT_EQ(report.regions, 0u);
    EXPECT_THROW(findRoomScaleRegions(scene, rays, settingsWithRoomFraction(-1.0)), std::invalid_argument);
}
