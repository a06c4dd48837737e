// The Cornell box at the medium preset, end to end: the path tracer on the same texels agrees with the lightmaps
// per surface within 5 % (issue "reference"), and bake.json's per-surface agreement of lightmap and elements is
// reported for every surface. Texel density is lowered (32 texels/m) to keep the suite quick; every other
// setting is the preset's.
//
// The lightmaps issue's own check (lightmap and elements within 1 % per surface) runs on the default bake, at the
// default density, below: the floor used to be 1.4 % off because its elements straddling the blocks' footprints
// averaged the covered part in (baker/exposed_area.h); measured now ≤ 0.6 % everywhere but the light (0.4–0.9 %
// over seeds 1–3; its elements share their plane with the ceiling and run a little high).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/gltf_fixture.h"
#include "support/gltf_validator.h"

using hemibake::test::runHemibake;
using hemibake::test::TempDir;

namespace {

double channelSum(const nlohmann::json& rgb) { return rgb[0].get<double>() + rgb[1].get<double>() + rgb[2].get<double>(); }

}  // namespace

TEST(CliCornellMedium, LightmapsAgreeWithTheSolverAndThePathTracer) {
    TempDir dir;
    const std::string out = dir.file("bake"), ref = dir.file("ref");
    const auto bake = runHemibake({"bake", hemibake::test::sharedScene("cornell_box.gltf"), "-o", out, "--preset", "medium",
                                   "--texels-per-unit", "32"});
    ASSERT_EQ(bake.exitCode, 0) << bake.err;
    EXPECT_GLBS_VALID(out);
    const nlohmann::json report = nlohmann::json::parse(std::ifstream(out + "/bake.json"));

    // Lightmap vs elements, per surface, over the same texels (texels inside geometry left out).
    const nlohmann::json& agreement = report["lightmap"]["surfaceAgreement"];
    ASSERT_EQ(agreement["surfaces"].size(), 8u);
    for (const auto& s : agreement["surfaces"]) {
        EXPECT_GT(s["texels"].get<int>(), 10) << s["node"];
        // The bound the path tracer check uses: the two computations of one quantity must not be further apart
        // than either is from the truth.
        EXPECT_LT(s["relativeDifference"].get<double>(), 0.05)
            << s["node"] << ": elements " << s["elementMeanIrradianceOverPi"] << ", lightmap " << s["lightmapMeanIrradianceOverPi"];
    }
    double worst = 0.0;
    for (const auto& s : agreement["surfaces"]) worst = std::max(worst, s["relativeDifference"].get<double>());
    EXPECT_DOUBLE_EQ(agreement["maxRelativeDifference"].get<double>(), worst);

    // Lightmap vs path tracer on exactly these texels. 256 spp: the per-surface mean's noise is < 0.3 %.
    const auto r = runHemibake({"reference", "--texels", out, "-o", ref, "--spp", "256"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto c = runHemibake({"compare", out, ref, "--json"});
    ASSERT_EQ(c.exitCode, 0) << c.err;
    const nlohmann::json cj = nlohmann::json::parse(c.out);
    ASSERT_EQ(cj["primitives"].size(), 8u);
    for (const auto& p : cj["primitives"]) {
        const double a = channelSum(p["errors"]["meanA"]), b = channelSum(p["errors"]["meanB"]);
        EXPECT_NEAR(a / b, 1.0, 0.05) << p["node"];
    }
}

// Issue 5, as written: `hemibake bake cornell_box.gltf -o out/` with every default, and per surface the mean of
// the lightmap and the mean of the solver's elements over the same texels agree within 1 %; the atlas is at least
// 60 % used; no texel is NaN or infinite (the bake compared with itself would then not score exactly 0).
TEST(CliCornellMedium, DefaultBakeAgreesWithItsElementsWithinOnePercent) {
    TempDir dir;
    const std::string out = dir.file("bake");
    const auto bake = runHemibake({"bake", hemibake::test::sharedScene("cornell_box.gltf"), "-o", out});
    ASSERT_EQ(bake.exitCode, 0) << bake.err;
    EXPECT_GLBS_VALID(out);
    const nlohmann::json report = nlohmann::json::parse(std::ifstream(out + "/bake.json"));
    EXPECT_EQ(report["settings"]["preset"], "medium");
    const nlohmann::json& agreement = report["lightmap"]["surfaceAgreement"];
    ASSERT_EQ(agreement["surfaces"].size(), 8u);
    for (const auto& s : agreement["surfaces"])
        EXPECT_LT(s["relativeDifference"].get<double>(), 0.01)
            << s["node"] << ": elements " << s["elementMeanIrradianceOverPi"] << ", lightmap " << s["lightmapMeanIrradianceOverPi"];
    for (const auto& a : report["lightmap"]["atlases"]) EXPECT_GE(a["utilization"].get<double>(), 0.6);
    EXPECT_LT(report["lightmap"]["seams"]["maxRelativeAfter"].get<double>(), 0.02);
    const auto self = runHemibake({"compare", out, out, "--json"});
    ASSERT_EQ(self.exitCode, 0) << self.err;
    const nlohmann::json g = nlohmann::json::parse(self.out)["global"];
    EXPECT_EQ(g["meanRelativeError"].get<double>(), 0.0);
    EXPECT_EQ(g["maxRelativeError"].get<double>(), 0.0);
}
