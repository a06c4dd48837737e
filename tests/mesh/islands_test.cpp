// Islands (mesh/islands.h): which parts group together, and the lengths each island gets.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mesh/islands.h"
#include "mesh/scene_builder.h"

using namespace hemibake;

namespace {

Bounds box(const glm::dvec3& lo, const glm::dvec3& hi) {
    Bounds b;
    b.extend(lo);
    b.extend(hi);
    return b;
}

Bounds unitCubeAt(const glm::dvec3& corner) { return box(corner, corner + glm::dvec3(1.0)); }

}  // namespace

// A part joins another when the gap between their boxes is at most the larger box's diagonal (√3 m for unit cubes).
TEST(SceneIslands, PartsJoinWithinTheLargerDiagonal) {
    const std::vector<Bounds> parts = {unitCubeAt({0, 0, 0}), unitCubeAt({2.7, 0, 0}), unitCubeAt({2.0, 2.0, 2.0})};
    // Gaps: 0–1 is 1.7 ≤ √3; 0–2 is √3 exactly (joins); 1–2 is √(0.7² + 1² + 1²) = 1.57 (joins).
    const SceneIslands islands(parts, glm::dvec3(0.0));
    EXPECT_EQ(islands.size(), 1u);
    const SceneIslands apart(std::vector<Bounds>{unitCubeAt({0, 0, 0}), unitCubeAt({2.74, 0, 0})}, glm::dvec3(0.0));
    ASSERT_EQ(apart.size(), 2u);  // a gap of 1.74 > √3
    EXPECT_EQ(apart.islandOfPart(0), 0u);
    EXPECT_EQ(apart.islandOfPart(1), 1u);
}

// Joining is transitive through a chain, and a small part beside a large one joins it (the larger diagonal counts).
TEST(SceneIslands, ChainsAndSmallPartsBesideLargeOnes) {
    std::vector<Bounds> parts;
    for (int k = 0; k < 50; ++k) parts.push_back(unitCubeAt({2.5 * k, 0, 0}));  // gaps of 1.5
    parts.push_back(box({-20.0, 0, 0}, {-19.99, 0.01, 0.01}));                   // 0.5 m above a 200 m floor
    parts.push_back(box({-200.0, -50.0, -1.0}, {0.0, 50.0, -0.5}));
    const SceneIslands islands(parts, glm::dvec3(0.0));
    EXPECT_EQ(islands.size(), 1u);
    EXPECT_EQ(islands.bounds(0).min.x, -200.0);
    EXPECT_EQ(islands.bounds(0).max.x, 2.5 * 49 + 1.0);
}

// Copies of a room a kilometre apart are islands of their own, numbered by their lowest part, whatever the order.
TEST(SceneIslands, CopiesKilometresApartAreSeparateIslands) {
    std::vector<Bounds> parts;
    for (int copy : {2, 0, 1})
        for (int k = 0; k < 3; ++k) parts.push_back(box({1000.0 * copy + k, 0, 0}, {1000.0 * copy + k + 1.0, 3, 3}));
    const SceneIslands islands(parts, glm::dvec3(1000.0, 1.5, 1.5));
    ASSERT_EQ(islands.size(), 3u);
    for (std::size_t p = 0; p < parts.size(); ++p) EXPECT_EQ(islands.islandOfPart(p), p / 3) << p;
    EXPECT_EQ(islands.bounds(0).min.x, 2000.0);
    EXPECT_EQ(islands.bounds(0).max.x, 2003.0);
    EXPECT_EQ(islands.bounds(1).min.x, 0.0);
    EXPECT_DOUBLE_EQ(islands.bounds(2).diagonal(), std::sqrt(9.0 + 9.0 + 9.0));
    // Lookup: inside a box, just outside one, and far from all.
    EXPECT_EQ(islands.islandAt({2001.5, 1.0, 1.0}), 0u);
    EXPECT_EQ(islands.islandAt({-0.001, 1.0, 1.0}), 1u);
    EXPECT_EQ(islands.islandAt({1003.0, 3.0, 3.0}), 2u);  // on a corner
    EXPECT_EQ(islands.islandAt({1400.0, 0.0, 0.0}), 2u);  // the nearest
    EXPECT_EQ(islands.islandAt({1e7, 0.0, 0.0}), 0u);
}

// lengthM: the island's relative length, raised to floatSteps float steps at its farthest coordinate from the frame
// centre. One island never reaches the floor for floatSteps ≤ relative × 2²⁴, wherever the scene lies.
TEST(SceneIslands, LengthsAreRelativeUnlessFloatStepsAreLarger) {
    const glm::dvec3 centre(1000.0, 1.5, 1.5);
    const std::vector<Bounds> parts = {box({0, 0, 0}, {3, 3, 3}), box({1997, 0, 0}, {2000, 3, 3})};
    const SceneIslands islands(parts, centre);
    ASSERT_EQ(islands.size(), 2u);
    const double diagonal = std::sqrt(27.0);
    EXPECT_EQ(islands.lengthM(0, 4e-6, 0.0), 4e-6 * diagonal);
    EXPECT_EQ(islands.lengthM(0, 4e-6, 4.0), 4.0 * 1000.0 * 0x1p-23);  // 0.48 mm > 21 µm
    EXPECT_EQ(islands.lengthM(1, 4e-6, 4.0), 4.0 * 1000.0 * 0x1p-23);
    EXPECT_EQ(islands.largestLengthM(1e-7, 0.0), 1e-7 * diagonal);
    EXPECT_EQ(islands.lengthAtM({1998.0, 1.0, 1.0}, 1e-5, 0.0), 1e-5 * diagonal);

    for (const double offsetM : {0.0, 1e5, -3e6}) {
        const glm::dvec3 lo(offsetM, offsetM, 0.0), hi(offsetM + 1e-3, offsetM + 2e-3, 5e-4);  // a 2.3 mm scene
        const SceneIslands one(std::vector<Bounds>{box(lo, hi)}, 0.5 * (lo + hi));
        ASSERT_EQ(one.size(), 1u);
        EXPECT_EQ(one.lengthM(0, 4e-6, 67.0), 4e-6 * box(lo, hi).diagonal()) << offsetM;
    }
}

// Empty parts (no vertices) and non-finite ones make islands of their own that lookups never return; no parts at all,
// no islands.
TEST(SceneIslands, EmptyPartsAndNoParts) {
    Bounds notFinite = unitCubeAt({5, 5, 5});
    notFinite.max.y = std::nan("");
    const std::vector<Bounds> parts = {Bounds{}, unitCubeAt({5, 5, 5}), Bounds{}, notFinite};
    const SceneIslands islands(parts, glm::dvec3(5.5));
    EXPECT_EQ(islands.size(), 4u);
    EXPECT_TRUE(islands.bounds(3).empty());
    EXPECT_EQ(islands.islandOfPart(1), 1u);
    EXPECT_EQ(islands.islandAt({0, 0, 0}), 1u);
    EXPECT_EQ(islands.lengthM(0, 1.0, 1.0), 0.0);
    const SceneIslands none(std::vector<Bounds>{}, glm::dvec3(0.0));
    EXPECT_EQ(none.size(), 0u);
    EXPECT_EQ(none.islandAt({1, 2, 3}), 0u);
    EXPECT_EQ(none.largestLengthM(1.0, 1.0), 0.0);
}

// From a scene: instances are the parts, the scene's bounds' centre the frame centre.
TEST(SceneIslands, OfASceneGroupsItsInstances) {
    SceneBuilder b;
    const int m = b.addMaterial(glm::vec3(0.5f));
    b.addQuad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, m);
    b.addQuad({0, 0, 0.5}, {1, 0, 0.5}, {1, 1, 0.5}, {0, 1, 0.5}, m);
    b.addQuad({3000, 0, 0}, {3001, 0, 0}, {3001, 1, 0}, {3000, 1, 0}, m);
    const Scene scene = b.build();
    const SceneIslands islands = SceneIslands::ofScene(scene);
    ASSERT_EQ(islands.size(), 2u);
    EXPECT_EQ(islands.islandOfPart(0), 0u);
    EXPECT_EQ(islands.islandOfPart(1), 0u);
    EXPECT_EQ(islands.islandOfPart(2), 1u);
    EXPECT_EQ(islands.lengthM(1, 0.0, 1.0), 1500.5 * 0x1p-23);  // the centre is at x = 1500.5
}
