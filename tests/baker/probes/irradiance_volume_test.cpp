// baker/irradiance_volume + baker/volume_lookup + baker/probe_io: a real baked volume (OSMesa cube maps) and
// the leak test of GROUND_TRUTH §7, plus the file round trip.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "baker/probes/irradiance_volume.h"
#include "baker/probes/probe_io.h"
#include "baker/probes/volume_lookup.h"
#include "mesh/errors.h"
#include "support/gltf_fixture.h"
#include "support/raster_fixtures.h"

namespace hemibake {
namespace {

using test::TriangleSoup;

// Two closed rooms side by side, x ∈ [−1, −w] and [w, 1] (y, z ∈ [0, 1]), separated by a wall 2w = 2 cm thick.
// Every surface of the left room emits L_e = 1 (ρ = 0), so its probes see E/π = 1 for every normal; the right
// room is black. Probes at x = −1/3 and +1/3 straddle the wall: naive trilinear interpolation leaks
// E0·(h − x)/h into the dark room (§7).
struct TwoRooms {
    PatchMesh mesh;
    std::vector<glm::vec3> radiance;
    IrradianceVolumeData volume;
    VolumeBakeStats stats;
};

const TwoRooms& twoRooms() {
    static const TwoRooms rooms = [] {
        TwoRooms r;
        const double w = 0.01;
        TriangleSoup both;  // lit room's triangles first
        both.addInwardBox({-1, 0, 0}, {-w, 1, 1}, 4);
        const std::size_t litTriangles = both.size();
        both.addInwardBox({w, 0, 0}, {1, 1, 1}, 4);
        r.mesh = both.build();
        for (auto& rho : r.mesh.elements.reflectance) rho = glm::vec3(0.0f);
        r.radiance.assign(r.mesh.elements.size(), glm::vec3(0.0f));
        for (std::size_t e = 0; e < litTriangles; ++e) r.radiance[e] = glm::vec3(1.0f);
        ProbeBakeSettings ps;
        ps.resolution = 32;
        ProbeBaker baker(r.mesh, r.radiance, glm::vec3(0.0f), ps);
        VolumeGridSettings grid;
        Bounds box;
        box.min = {-1.0, 0.1, 0.1};
        box.max = {1.0, 0.9, 0.9};
        grid.box = box;
        grid.resolution = {4, 3, 3};  // x = −1, −1/3, 1/3, 1: the wall lies midway between the middle planes
        const VolumeGrid plan = planVolumeGrid(Bounds{}, grid);
        r.volume = bakeIrradianceVolume(baker, plan, grid, r.stats);
        return r;
    }();
    return rooms;
}

TEST(IrradianceVolume, GridPlanning) {
    Bounds scene;
    scene.min = {0, 0, 0};
    scene.max = {0.556, 0.5488, 0.5592};
    VolumeGridSettings s;
    s.spacingM = 0.1;
    const VolumeGrid g = planVolumeGrid(scene, s);
    EXPECT_EQ(g.resolution, glm::ivec3(7, 7, 7));
    const double inset = kSceneBoundsInsetPerDiagonal * scene.diagonal();
    EXPECT_NEAR(g.min.x, inset, 1e-12);
    EXPECT_NEAR(g.max.y, 0.5488 - inset, 1e-12);
    s.spacingM = 0.0;
    s.resolution = {1, 2, 2};
    EXPECT_THROW(planVolumeGrid(scene, s), std::invalid_argument);
}

TEST(IrradianceVolume, ThinWallDoesNotLeak) {
    const TwoRooms& r = twoRooms();
    ASSERT_EQ(r.volume.probeCount(), 36u);
    EXPECT_EQ(r.stats.invalid, 0u);
    // The lit room's probes see E/π = 1 in every direction, the dark room's 0.
    const glm::dvec3 up(0, 1, 0);
    EXPECT_NEAR(r.volume.sh[r.volume.index(1, 1, 1)].irradianceOverPi(up).x, 1.0, 0.01);
    EXPECT_NEAR(r.volume.sh[r.volume.index(2, 1, 1)].irradianceOverPi(up).x, 0.0, 1e-6);

    VolumeLookupOptions naive;
    naive.weighting = VolumeWeighting::Naive;
    double worstRatio = 0.0;
    for (double x : {0.05, 0.1, 0.2, 0.3})
        for (const glm::dvec3& n : {glm::dvec3(1, 0, 0), glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, -1)}) {
            const glm::dvec3 p(x, 0.5, 0.45);
            const double leaky = sampleIrradianceVolume(r.volume, p, n, naive).irradianceOverPi.x;
            const VolumeSample aware = sampleIrradianceVolume(r.volume, p, n);
            // Naive interpolation reproduces §7's linear leak E0·(h − x)/h, h = 2/3 from the lit plane at −1/3.
            EXPECT_NEAR(leaky, (1.0 / 3.0 - x) / (2.0 / 3.0), 0.02) << "x " << x;
            const double ratio = aware.irradianceOverPi.x / leaky;
            std::printf("dark side x=%.2f n=(%g,%g,%g): naive %.4f, visibility-aware %.5f, ratio %.4f\n", x, n.x, n.y, n.z,
                        leaky, aware.irradianceOverPi.x, ratio);
            // Known limit (docs/probes.md): a surface facing the wall from closer than ~1/10 of the spacing has
            // the occluded lit probes in front and the dark ones behind it; it keeps at most 10 % of the naive leak
            // (8.7 % measured), not the 5 % of the rest.
            if (x < 0.1 && n.x < 0.0) {
                EXPECT_LT(ratio, 0.1) << "x " << x << ", facing the wall";
                continue;
            }
            worstRatio = std::max(worstRatio, ratio);
            EXPECT_LT(ratio, 0.05) << "x " << x;
        }
    std::printf("thin wall: worst asserted visibility-aware / naive on the dark side = %.4f\n", worstRatio);
    // And the lit side keeps its light: dark probes behind the wall do not pull it down.
    for (const glm::dvec3& n : {glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0)}) {
        const double lit = sampleIrradianceVolume(r.volume, {-0.1, 0.5, 0.45}, n).irradianceOverPi.x;
        std::printf("lit side x=-0.10 n=(%g,%g,%g): visibility-aware %.4f (naive %.4f)\n", n.x, n.y, n.z, lit,
                    sampleIrradianceVolume(r.volume, {-0.1, 0.5, 0.45}, n, naive).irradianceOverPi.x);
        EXPECT_GT(lit, 0.95);
    }
}

TEST(IrradianceVolume, ProbesInsideTheWallAreRelocatedOrInvalid) {
    const TwoRooms& r = twoRooms();
    ProbeBaker baker(r.mesh, r.radiance, glm::vec3(0.0f), ProbeBakeSettings{});
    VolumeGridSettings grid;
    Bounds box;
    box.min = {-0.5, 0.25, 0.25};
    box.max = {0.5, 0.75, 0.75};
    grid.box = box;
    grid.resolution = {3, 2, 2};  // x = 0 is inside the wall
    VolumeBakeStats stats;
    const IrradianceVolumeData v = bakeIrradianceVolume(baker, planVolumeGrid(Bounds{}, grid), grid, stats);
    EXPECT_EQ(stats.relocated, 4u);
    EXPECT_EQ(stats.invalid, 0u);
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y) {
            const glm::dvec3 moved = v.probePosition(1, y, z);
            EXPECT_GT(std::abs(moved.x), 0.01);  // out of the wall
            EXPECT_LE(std::abs(moved.x), 0.5 * 0.5 + 1e-9);
        }
}

TEST(ProbeIo, VolumeRoundTripAndProbePositions) {
    namespace fs = std::filesystem;
    const TwoRooms& r = twoRooms();
    const hemibake::test::TempDir temp;  // unique per run: suites of concurrent checkouts must not share it
    const fs::path dir = temp.path() / "volume";
    const auto files = writeIrradianceVolume(dir, r.volume, ProbeBakeSettings{}, r.stats);
    EXPECT_EQ(files.size(), 3u);
    EXPECT_EQ(fs::file_size(dir / "volume.bin"), r.volume.probeCount() * kVolumeRecordBytes);
    const IrradianceVolumeData back = readIrradianceVolume(dir);
    EXPECT_EQ(back.resolution, r.volume.resolution);
    EXPECT_EQ(back.valid, r.volume.valid);
    EXPECT_EQ(back.depthResolution, r.volume.depthResolution);
    for (std::size_t i = 0; i < back.probeCount(); ++i)
        for (int k = 0; k < kShCoefficients; ++k)
            EXPECT_NEAR(back.sh[i].c[std::size_t(k)].y, r.volume.sh[i].c[std::size_t(k)].y, 1e-6);
    const glm::dvec3 p(0.2, 0.5, 0.45), n(1, 0, 0);
    EXPECT_NEAR(sampleIrradianceVolume(back, p, n).irradianceOverPi.x,
                sampleIrradianceVolume(r.volume, p, n).irradianceOverPi.x, 1e-5);

    std::ofstream(dir / "good.json") << R"({"positions": [[1, 2, 3], [-0.5, 0, 1e-3]]})";
    const auto positions = readProbePositions(dir / "good.json");
    ASSERT_EQ(positions.size(), 2u);
    EXPECT_EQ(positions[1], glm::dvec3(-0.5, 0, 1e-3));
    for (const char* bad : {R"({"positions": [[1, 2]]})", R"({"where": []})", R"({"positions": [[1, 2, "x"]]})", "{oops"}) {
        std::ofstream(dir / "bad.json") << bad;
        try {
            readProbePositions(dir / "bad.json");
            ADD_FAILURE() << "accepted " << bad;
        } catch (const InputError& e) {
            const std::string message = e.what();
            EXPECT_EQ(message.rfind((dir / "bad.json").string() + ": ", 0), 0u) << message;
            EXPECT_EQ(message.find('\n'), std::string::npos) << message;
        }
    }
    EXPECT_THROW(readProbePositions(dir / "missing.json"), InputError);
    fs::remove(dir / "volume.bin");
    EXPECT_THROW(readIrradianceVolume(dir), InputError);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace hemibake
