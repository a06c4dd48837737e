// Issue 15: no light through a wall as artists build it. Two rooms share one continuous floor slab and one continuous
// ceiling slab; the wall between them reaches 5 cm into both slabs, as do the four outer walls. Room A is lit by a
// panel under its ceiling, room B is sealed. Every texel in room B must stay at most 1e-4 of room A's mean: a slab
// element or patch running under the wall, a texel sampled on the wrong side, or a refill across the wall's foot
// would carry light into B (before faces were cut along solids, the brightest texel in B was 2e-3 of A's mean).
#include <cstdio>

#include <gtest/gtest.h>

#include "baker/pipeline/bake_scene.h"
#include "baker/pipeline/presets.h"
#include "mesh/scene_builder.h"

using namespace hemibake;

namespace {

// A closed, outward-facing box as one instance (SceneBuilder::addBox makes six open quads, which are no solid).
void addSolidBox(SceneBuilder& b, const glm::dvec3& lo, const glm::dvec3& hi, int material, const std::string& name) {
    std::vector<glm::dvec3> c;
    for (int i = 0; i < 8; ++i) c.emplace_back(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    std::vector<std::array<int, 3>> tris;
    for (const auto& q : quads) {
        tris.push_back({q[0], q[1], q[2]});
        tris.push_back({q[0], q[2], q[3]});
    }
    b.addTriangles(c, tris, material, name);
}

struct RoomMeans {
    double litMean = 0.0;   // mean E/π over room A's texels (luminance-free: the channel mean)
    double darkMax = 0.0;   // brightest texel in room B
    std::size_t litTexels = 0, darkTexels = 0;
};

// Rooms: A is x 0..2, B is x 2+w..4+w; both y 0..2.5, z 0..3. Texel sample points are nudged off their surface, so
// a texel of a room's floor, walls or ceiling lies inside that room's air.
RoomMeans bakeTwoRooms(double wallM, bool cutAlongSolids) {
    SceneBuilder b("two rooms");
    const int grey = b.addMaterial(glm::vec3(0.6f));
    const int lamp = b.addMaterial(glm::vec3(0.5f), glm::vec3(10.0f));
    const double east = 4.0 + wallM;
    addSolidBox(b, {-0.2, -0.2, -0.2}, {east + 0.2, 0.0, 3.2}, grey, "floor slab");
    addSolidBox(b, {-0.2, 2.5, -0.2}, {east + 0.2, 2.7, 3.2}, grey, "ceiling slab");
    addSolidBox(b, {-0.2, -0.05, -0.2}, {0.0, 2.55, 3.2}, grey, "west wall");
    addSolidBox(b, {east, -0.05, -0.2}, {east + 0.2, 2.55, 3.2}, grey, "east wall");
    addSolidBox(b, {-0.2, -0.05, -0.2}, {east + 0.2, 2.55, 0.0}, grey, "south wall");
    addSolidBox(b, {-0.2, -0.05, 3.0}, {east + 0.2, 2.55, 3.2}, grey, "north wall");
    addSolidBox(b, {2.0, -0.05, -0.1}, {2.0 + wallM, 2.55, 3.1}, grey, "middle wall");
    // The panel faces down, 1 cm under room A's ceiling.
    b.addQuad({0.7, 2.49, 1.0}, {0.7, 2.49, 2.0}, {1.3, 2.49, 2.0}, {1.3, 2.49, 1.0}, lamp, "panel");
    Scene scene = b.build();

    BakeSettings settings = presetSettings("medium", scene.bounds().diagonal());
    settings.lightmap.texelsPerUnit = 8.0;
    settings.solve.subdivision.cutAlongSolids = cutAlongSolids;
    settings.solve.lighting.skyRadiance = glm::vec3(1.0f);  // the outside is lit; room B sees none of it
    const BakeResult r = bakeScene(scene, settings, BakeOutput{});

    RoomMeans m;
    for (std::size_t a = 0; a < r.texels.size(); ++a)
        for (std::size_t i = 0; i < r.texels[a].count(); ++i) {
            const glm::dvec3 p = r.texels[a].position[i];
            if (!(p.y > 0.0 && p.y < 2.5 && p.z > 0.0 && p.z < 3.0)) continue;
            const glm::vec3 e = r.lightmaps[a].irradianceOverPi[r.lightmaps[a].index(r.texels[a].x[i], r.texels[a].y[i])];
            const double v = (double(e.x) + double(e.y) + double(e.z)) / 3.0;
            if (p.x > 0.0 && p.x < 2.0) {
                m.litMean += v;
                ++m.litTexels;
            } else if (p.x > 2.0 + wallM && p.x < east) {
                m.darkMax = std::max(m.darkMax, v);
                ++m.darkTexels;
            }
        }
    m.litMean /= double(std::max<std::size_t>(m.litTexels, 1));
    std::printf("wall %.2f m, cuts %s: lit mean E/pi %.4f over %zu texels, dark max %.3g (%.3g of the lit mean) over %zu texels\n",
                wallM, cutAlongSolids ? "on" : "off", m.litMean, m.litTexels, m.darkMax, m.darkMax / m.litMean, m.darkTexels);
    return m;
}

}  // namespace

TEST(WallOnSlabs, NoLightThroughAWallOfTwentyCentimetres) {
    const RoomMeans m = bakeTwoRooms(0.2, true);
    ASSERT_GT(m.litTexels, 1000u);  // about 2,400 per room at 8 texels/m
    ASSERT_GT(m.darkTexels, 1000u);
    EXPECT_GT(m.litMean, 0.1);  // the panel lights room A
    EXPECT_LE(m.darkMax, 1e-4 * m.litMean) << "dark room's brightest texel " << m.darkMax / m.litMean << " of the lit mean";
}

TEST(WallOnSlabs, NoLightThroughAWallOfFiveCentimetres) {
    const RoomMeans m = bakeTwoRooms(0.05, true);
    ASSERT_GT(m.darkTexels, 1000u);
    EXPECT_GT(m.litMean, 0.1);
    EXPECT_LE(m.darkMax, 1e-4 * m.litMean) << "dark room's brightest texel " << m.darkMax / m.litMean << " of the lit mean";
}

TEST(WallOnSlabs, WithoutCutsTheSlabsCarryLightUnderTheWall) {
    // The same bake with faces left uncut: the check above can fail.
    const RoomMeans m = bakeTwoRooms(0.2, false);
    EXPECT_GT(m.darkMax, 1e-4 * m.litMean);
}
