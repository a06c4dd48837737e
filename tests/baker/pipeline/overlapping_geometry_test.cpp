// Issue 15: geometry as artists build it (parts that overlap) lit as if it did not overlap.
//
// No light through a wall: Two rooms share one continuous floor slab and one continuous
// ceiling slab; the wall between them reaches 5 cm into both slabs, as do the four outer walls. Room A is lit by a
// panel under its ceiling, room B is sealed. Every texel in room B must stay at most 1e-4 of room A's mean: a slab
// element or patch running under the wall, a texel sampled on the wrong side, or a refill across the wall's foot
// would carry light into B (before faces were cut along solids, the brightest texel in B was 2e-3 of A's mean).
#include <cstdio>

#include <gtest/gtest.h>

#include "baker/pipeline/bake_scene.h"
#include "baker/pipeline/presets.h"
#include "baker/rays/embree_scene.h"
#include "baker/reference/progressive_reference.h"
#include "mesh/scene_builder.h"
#include "support/test_meshes.h"

using namespace hemibake;
using hemibake::test::addSolidBox;

namespace {

struct RoomMeans {
    double litMean = 0.0;   // mean E/π over room A's texels (luminance-free: the channel mean)
    double darkMax = 0.0;   // brightest texel in room B
    double underWallMax = 0.0;  // brightest slab texel under the middle wall (inside geometry, refilled)
    std::size_t litTexels = 0, darkTexels = 0, underWallTexels = 0;
};

// Rooms: A is x 0..2, B is x 2+w..4+w; both y 0..2.5, z 0..3. Texel sample points are nudged off their surface, so
// a texel of a room's floor, walls or ceiling lies inside that room's air.
RoomMeans bakeTwoRooms(double wallM, bool cutAlongSolids, double unevenShotSpread = SolverSettings{}.unevenShotSpread,
                       RowSampling rows = SolverSettings{}.rowSampling) {
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
    settings.solve.solver.unevenShotSpread = unevenShotSpread;
    settings.solve.solver.rowSampling = rows;
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
            } else if (p.x > 2.0 && p.x < 2.0 + wallM) {
                m.underWallMax = std::max(m.underWallMax, v);
                ++m.underWallTexels;
            }
        }
    m.litMean /= double(std::max<std::size_t>(m.litTexels, 1));
    std::printf("wall %.2f m, cuts %s: lit mean E/pi %.4f over %zu texels, dark max %.3g (%.3g of the lit mean) over %zu "
                "texels, under the wall max %.3g over %zu texels\n",
                wallM, cutAlongSolids ? "on" : "off", m.litMean, m.litTexels, m.darkMax, m.darkMax / m.litMean, m.darkTexels,
                m.underWallMax / m.litMean, m.underWallTexels);
    return m;
}

}  // namespace

TEST(WallOnSlabs, NoLightThroughAWallOfTwentyCentimetres) {
    const RoomMeans m = bakeTwoRooms(0.2, true);
    ASSERT_GT(m.litTexels, 1000u);  // about 2,400 per room at 8 texels/m
    ASSERT_GT(m.darkTexels, 1000u);
    EXPECT_GT(m.litMean, 0.1);  // the panel lights room A
    EXPECT_LE(m.darkMax, 1e-4 * m.litMean) << "dark room's brightest texel " << m.darkMax / m.litMean << " of the lit mean";
    // The slab texels under the wall are refilled from the dark side, so a GPU's bilinear filter reads no light into
    // room B at the wall's foot (averaging both sides would put half the lit floor's value there).
    ASSERT_GT(m.underWallTexels, 20u);
    EXPECT_LE(m.underWallMax, 1e-4 * m.litMean) << "under the wall " << m.underWallMax / m.litMean << " of the lit mean";
}

TEST(WallOnSlabs, NoLightThroughAWallOfFiveCentimetres) {
    const RoomMeans m = bakeTwoRooms(0.05, true);
    ASSERT_GT(m.darkTexels, 1000u);
    EXPECT_GT(m.litMean, 0.1);
    EXPECT_LE(m.darkMax, 1e-4 * m.litMean) << "dark room's brightest texel " << m.darkMax / m.litMean << " of the lit mean";
}

TEST(WallOnSlabs, WithoutCutsTheSlabsCarryLightUnderTheWall) {
    // The same bake with faces left uncut and every patch shooting from its centre (hemicube rows: rows by rays leave
    // from where the light was put in, even with uneven shots off): the check above can fail. (Shooting uneven light
    // from where it landed already keeps most of it on its side: 7.4e-5 without cuts.)
    const RoomMeans m = bakeTwoRooms(0.2, false, 1.0, RowSampling::Hemicube);
    EXPECT_GT(m.darkMax, 1e-4 * m.litMean);
}

// A 0.5 m box sunk 2 cm into a floor slab under a uniform sky: the floor texels in a 0.5 m ring around it agree with
// the path tracer on the same texels within 3 %, and none is brighter than the open floor 2 m away (the box only
// takes sky away; under a sky alone its reflection does not give it back). Exposed-area trimming already got this
// right before faces were cut (worst texel 2.8 % without cuts, 2.3 % with). Since rows by rays leave from over the
// whole patch (session 33): 2.82 % (2.61–3.00 % over seeds 1–5), the foot's texels a little brighter.
TEST(SunkBox, FloorAroundItMatchesThePathTracer) {
    SceneBuilder b("sunk box");
    const int grey = b.addMaterial(glm::vec3(0.5f));
    addSolidBox(b, {-3.0, -0.2, -3.0}, {3.0, 0.0, 3.0}, grey, "floor slab");
    addSolidBox(b, {-0.25, -0.02, -0.25}, {0.25, 0.48, 0.25}, grey, "box");
    const Scene scene = b.build();
    BakeSettings settings = presetSettings("medium", scene.bounds().diagonal());
    settings.lightmap.texelsPerUnit = 16.0;
    settings.solve.lighting.skyRadiance = glm::vec3(1.0f);
    const BakeResult r = bakeScene(scene, settings, BakeOutput{});

    std::vector<SurfacePoint> ring;
    std::vector<double> baked;
    double openSum = 0.0;
    std::size_t open = 0;
    for (std::size_t a = 0; a < r.texels.size(); ++a)
        for (std::size_t i = 0; i < r.texels[a].count(); ++i) {
            const glm::dvec3 p = r.texels[a].position[i];
            if (r.texels[a].normal[i].y < 0.99f || std::abs(p.y) > 0.01) continue;
            const double d = std::max(std::abs(p.x), std::abs(p.z));  // distance from the box's centre, square rings
            const glm::vec3 e = r.lightmaps[a].irradianceOverPi[r.lightmaps[a].index(r.texels[a].x[i], r.texels[a].y[i])];
            const double v = (double(e.x) + double(e.y) + double(e.z)) / 3.0;
            if (d > 0.25 && d < 0.75) {
                ring.push_back({p, r.texels[a].normal[i]});
                baked.push_back(v);
            } else if (d > 2.0 && d < 2.5) {
                openSum += v;
                ++open;
            }
        }
    ASSERT_GT(ring.size(), 400u);
    ASSERT_GT(open, 400u);
    const double openMean = openSum / double(open);

    const EmbreeScene rays(scene);
    PathTracerSettings tracer;
    tracer.skyRadiance = glm::vec3(1.0f);
    ProgressiveSettings progressive;
    progressive.spp = 4096;  // per-texel standard error ≈ 0.4 % here
    const ProgressiveEstimate ref = irradianceOverPiProgressively(scene, rays, tracer, ring, progressive);
    double worst = 0.0, bakedMax = 0.0, sumBaked = 0.0, sumRef = 0.0;
    for (std::size_t i = 0; i < ring.size(); ++i) {
        const double v = (ref.mean[i].x + ref.mean[i].y + ref.mean[i].z) / 3.0;
        worst = std::max(worst, std::abs(baked[i] / v - 1.0));
        bakedMax = std::max(bakedMax, baked[i]);
        sumBaked += baked[i];
        sumRef += v;
    }
    std::printf("sunk box: %zu ring texels, mean %.4f (path tracer %.4f), worst texel %.2f %%, brightest %.4f, open floor %.4f\n",
                ring.size(), sumBaked / double(ring.size()), sumRef / double(ring.size()), 100.0 * worst, bakedMax, openMean);
    EXPECT_LE(worst, 0.03);
    EXPECT_LE(bakedMax, openMean);
}

// A light panel hung 5 cm under a ceiling, emitting from every face (a closed box, as the level generator and many
// artists make them): its top lights a hot spot on the ceiling that the panel hides from the room, and most of that
// light bounces back into the panel. Level-sized patches (3.3 m) and elements (1.6 m) average the hot spot over a
// whole patch; shot from the patch's centre, it lit the room as if the ceiling glowed everywhere (the table top
// 20 % too bright, the panel's top 45 % too dark in one room of the generated level). Elements halved where direct
// light steps (the hot spot's edge) and uneven light shot from the elements it landed on keep it in the gap.
namespace {

struct PanelRoom {
    double tableBaked = 0.0, tableTraced = 0.0;  // mean E/π over the table top's texels
    double floorBaked = 0.0, floorTraced = 0.0;  // and over the open floor's
    double panelTopBaked = 0.0, panelTopTraced = 0.0;  // and over the panel's top, 5 cm under the ceiling
    double gapBaked = 0.0, gapTraced = 0.0;      // and over the ceiling above the panel (the gap's other side)
    std::size_t facesCutAtGaps = 0;
};

struct PanelRoomOptions {
    double patchSizeM = 3.3;    // what the medium preset gave a 26 m level before patches stopped at 3.5 m
    double elementSizeM = 1.6;
    double unevenShotSpread = SolverSettings{}.unevenShotSpread;
    int directStepLevels = 0;
    bool texelDirect = true;    // the final gather sees direct light per texel (the default), else element averages
    int gapPasses = 0;          // re-gathers of the gap's texels (experimental, off by default)
    double gapCutFraction = SubdivisionSettings{}.gapCutFraction;
    RowSampling rows = SolverSettings{}.rowSampling;  // how the shooting rows are sampled
};

PanelRoom bakePanelRoom(const PanelRoomOptions& o) {
    SceneBuilder b("hanging panel");
    const int grey = b.addMaterial(glm::vec3(0.7f));
    const int lamp = b.addMaterial(glm::vec3(0.8f), glm::vec3(12.0f));
    addSolidBox(b, {-0.2, -0.2, -0.2}, {4.2, 0.0, 4.2}, grey, "floor slab");
    addSolidBox(b, {-0.2, 3.0, -0.2}, {4.2, 3.2, 4.2}, grey, "ceiling slab");
    addSolidBox(b, {-0.2, -0.05, -0.2}, {0.0, 3.05, 4.2}, grey, "west wall");
    addSolidBox(b, {4.0, -0.05, -0.2}, {4.2, 3.05, 4.2}, grey, "east wall");
    addSolidBox(b, {0.0, -0.05, -0.2}, {4.0, 3.05, 0.0}, grey, "south wall");
    addSolidBox(b, {0.0, -0.05, 4.0}, {4.0, 3.05, 4.2}, grey, "north wall");
    addSolidBox(b, {1.4, 2.9, 1.7}, {2.6, 2.95, 2.3}, lamp, "panel");
    addSolidBox(b, {2.5, 0.75, 2.5}, {3.5, 0.8, 3.5}, grey, "table top");
    Scene scene = b.build();
    BakeSettings settings = presetSettings("medium", scene.bounds().diagonal());
    settings.solve.subdivision.patchSizeM = o.patchSizeM;
    settings.solve.subdivision.elementSizeM = o.elementSizeM;
    settings.solve.subdivision.gapCutFraction = o.gapCutFraction;
    settings.solve.solver.unevenShotSpread = o.unevenShotSpread;
    settings.solve.directSteps.levels = o.directStepLevels;
    settings.solve.solver.rowSampling = o.rows;
    settings.lightmap.texelsPerUnit = 8.0;
    settings.lightmap.gatherTexelDirect = o.texelDirect;
    settings.lightmap.gapPasses = o.gapPasses;
    const BakeResult r = bakeScene(scene, settings, BakeOutput{});

    std::vector<SurfacePoint> table, floor, panelTop, gap;
    std::vector<double> tableBaked, floorBaked, panelTopBaked, gapBaked;
    for (std::size_t a = 0; a < r.texels.size(); ++a)
        for (std::size_t i = 0; i < r.texels[a].count(); ++i) {
            const glm::dvec3 p = r.texels[a].position[i];
            const glm::vec3 n = r.texels[a].normal[i];
            const glm::vec3 e = r.lightmaps[a].irradianceOverPi[r.lightmaps[a].index(r.texels[a].x[i], r.texels[a].y[i])];
            const double v = (double(e.x) + double(e.y) + double(e.z)) / 3.0;
            const bool underPanel = p.x > 1.4 && p.x < 2.6 && p.z > 1.7 && p.z < 2.3;
            if (n.y < -0.99f && std::abs(p.y - 3.0) < 0.01 && underPanel) gap.push_back({p, n}), gapBaked.push_back(v);
            if (n.y < 0.99f) continue;
            const bool onTable = std::abs(p.y - 0.8) < 0.01 && p.x > 2.5 && p.x < 3.5 && p.z > 2.5 && p.z < 3.5;
            const bool onFloor = std::abs(p.y) < 0.01 && p.x > 0.0 && p.x < 2.0 && p.z > 0.0 && p.z < 4.0;
            if (std::abs(p.y - 2.95) < 0.01 && underPanel) panelTop.push_back({p, n}), panelTopBaked.push_back(v);
            if (onTable) table.push_back({p, n}), tableBaked.push_back(v);
            if (onFloor) floor.push_back({p, n}), floorBaked.push_back(v);
        }
    EXPECT_GT(table.size(), 40u);
    EXPECT_GT(floor.size(), 400u);
    EXPECT_GT(panelTop.size(), 30u);
    EXPECT_GT(gap.size(), 30u);
    const EmbreeScene rays(scene);
    ProgressiveSettings progressive;
    progressive.spp = 2048;
    auto means = [&](const std::vector<SurfacePoint>& points, const std::vector<double>& baked, double& bakedMean, double& tracedMean) {
        const ProgressiveEstimate ref = irradianceOverPiProgressively(scene, rays, PathTracerSettings{}, points, progressive);
        for (std::size_t i = 0; i < points.size(); ++i) {
            bakedMean += baked[i] / double(points.size());
            tracedMean += (ref.mean[i].x + ref.mean[i].y + ref.mean[i].z) / 3.0 / double(points.size());
        }
    };
    PanelRoom room;
    room.facesCutAtGaps = r.solved->mesh.solidCuts.facesCutAtGaps;
    means(table, tableBaked, room.tableBaked, room.tableTraced);
    means(floor, floorBaked, room.floorBaked, room.floorTraced);
    means(panelTop, panelTopBaked, room.panelTopBaked, room.panelTopTraced);
    means(gap, gapBaked, room.gapBaked, room.gapTraced);
    std::printf("hanging panel, %.2f m patches / %.2f m elements, unevenShotSpread %.2f, %d direct-step levels, texel direct %d, "
                "%d gap passes, gap cuts %.3f (%zu faces): table top %+.2f %%, floor %+.2f %%, panel top %+.2f %%, "
                "ceiling over it %+.2f %% (against the path tracer)\n",
                o.patchSizeM, o.elementSizeM, o.unevenShotSpread, o.directStepLevels, int(o.texelDirect), o.gapPasses,
                o.gapCutFraction, room.facesCutAtGaps, 100.0 * (room.tableBaked / room.tableTraced - 1.0),
                100.0 * (room.floorBaked / room.floorTraced - 1.0), 100.0 * (room.panelTopBaked / room.panelTopTraced - 1.0),
                100.0 * (room.gapBaked / room.gapTraced - 1.0));
    return room;
}

}  // namespace

// Measured: table top −2.8 %, open floor −0.0 % (path tracer mean over 60 and 1,000 texels at 2,048 spp: its noise
// is below 0.3 %); the issue asks every room object within 5 %.
TEST(HangingPanel, LightFromTheGapStaysInTheGap) {
    PanelRoomOptions o;
    o.directStepLevels = 3;
    const PanelRoom r = bakePanelRoom(o);
    EXPECT_NEAR(r.tableBaked / r.tableTraced, 1.0, 0.04);
    EXPECT_NEAR(r.floorBaked / r.floorTraced, 1.0, 0.02);
    EXPECT_NEAR(r.panelTopBaked / r.panelTopTraced, 1.0, 0.07);
}

// The sizes the presets give a level (3.5 m patches, 1.75 m elements): the panel's outline cut into the ceiling
// keeps the gap's light on elements of its own, and the elements facing the gap shoot it from where it is. Measured:
// panel top +2.9 %, ceiling over it +0.8 %, table top −1.7 %, floor −1.4 %. Without the cut: −26.7 %, −22.6 %,
// +5.6 %, +11.6 % (the trapped light averaged with the open ceiling, and shot into the room from there).
TEST(HangingPanel, GapCutsKeepTheTrappedLightAtLevelSizes) {
    PanelRoomOptions o;
    o.patchSizeM = 3.5;
    o.elementSizeM = 1.75;
    const PanelRoom r = bakePanelRoom(o);
    EXPECT_GT(r.facesCutAtGaps, 0u);
    EXPECT_NEAR(r.panelTopBaked / r.panelTopTraced, 1.0, 0.05);
    EXPECT_NEAR(r.gapBaked / r.gapTraced, 1.0, 0.05);
    EXPECT_NEAR(r.tableBaked / r.tableTraced, 1.0, 0.03);
    EXPECT_NEAR(r.floorBaked / r.floorTraced, 1.0, 0.03);

    o.gapCutFraction = 0.0;
    const PanelRoom uncut = bakePanelRoom(o);
    EXPECT_EQ(uncut.facesCutAtGaps, 0u);
    EXPECT_LT(uncut.panelTopBaked / uncut.panelTopTraced, 0.85);
    EXPECT_GT(uncut.floorBaked / uncut.floorTraced, 1.05);
}

// The same with rows traced by rays (every preset): rays leave from stratified points over each element, except that
// an element facing a gap (half its rays ending within its size) shoots from its centroid, or from its 3 × 3 inset
// points in a tight gap, as a hemicube row. Measured: panel top +2.4 %, ceiling over it +0.6 %, table top −2.1 %,
// floor −1.3 %. Rays from uniform points over every element, gaps included (the exact area integral of a row) lost
// the gap's light into the room: −6.0 %, −4.6 %, +0.8 %, +2.1 %.
TEST(HangingPanel, RayRowsKeepTheTrappedLightAtLevelSizes) {
    PanelRoomOptions o;
    o.patchSizeM = 3.5;
    o.elementSizeM = 1.75;
    o.rows = RowSampling::Rays;
    const PanelRoom r = bakePanelRoom(o);
    EXPECT_NEAR(r.panelTopBaked / r.panelTopTraced, 1.0, 0.05);
    EXPECT_NEAR(r.gapBaked / r.gapTraced, 1.0, 0.05);
    EXPECT_NEAR(r.tableBaked / r.tableTraced, 1.0, 0.03);
    EXPECT_NEAR(r.floorBaked / r.floorTraced, 1.0, 0.03);
}

// The panel's top looks at the ceiling 5 cm above it. Without gap cuts (elements stay 1.6 m over the gap) the final
// gather reads the ceiling's direct light per texel, so the top sees the hot spot its own light makes there; through
// the elements' averages it is spread over 1.6 m. Measured: −27 % per texel, −44 % through the averages.
TEST(HangingPanel, PanelTopSeesTheDirectHotSpotPerTexel) {
    PanelRoomOptions o;
    o.gapCutFraction = 0.0;
    const PanelRoom perTexel = bakePanelRoom(o);
    o.texelDirect = false;
    const PanelRoom averaged = bakePanelRoom(o);
    EXPECT_LT(averaged.panelTopBaked / averaged.panelTopTraced, 0.7);
    EXPECT_GT(perTexel.panelTopBaked / perTexel.panelTopTraced, averaged.panelTopBaked / averaged.panelTopTraced + 0.1);
}

// Re-gathering the gap's texels until they settle (experimental, --gap-passes) brings the trapped light back at
// 8 texels/m without gap cuts: measured −6.2 % (the texels are 12.5 cm across a 5 cm gap; at 4 texels/m only −24 % → −20 %).
TEST(HangingPanel, GapPassesBringTheTrappedLightBack) {
    PanelRoomOptions o;
    o.gapCutFraction = 0.0;
    o.gapPasses = 16;
    const PanelRoom r = bakePanelRoom(o);
    EXPECT_NEAR(r.panelTopBaked / r.panelTopTraced, 1.0, 0.07);
}

// Without both (coarse elements, every patch shooting from its centre or area-weighted points): +16 % and +24 %.
// Hemicube rows, which shoot an even patch from its centre: rows by rays leave from where the light was put in, so
// they keep part of it in place even with uneven shots switched off.
TEST(HangingPanel, ShotFromThePatchCentreTheRoomIsTooBright) {
    PanelRoomOptions o;
    o.unevenShotSpread = 1.0;
    o.gapCutFraction = 0.0;
    o.rows = RowSampling::Hemicube;
    const PanelRoom r = bakePanelRoom(o);
    EXPECT_GT(r.tableBaked / r.tableTraced, 1.1);
    EXPECT_GT(r.floorBaked / r.floorTraced, 1.1);
}

