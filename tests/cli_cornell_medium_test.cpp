// The Cornell box at the medium preset, end to end: the path tracer on the same texels agrees with the lightmaps
// per surface within 5 % (issue "reference"), and bake.json's per-surface agreement of lightmap and elements is
// reported for every surface. Texel density is lowered (32 texels/m) to keep the suite quick; every other
// setting is the preset's.
//
// Not yet asserted: the lightmaps issue asks lightmap and elements to agree within 1 % per surface. Measured here:
// ceiling/blocks/light ≤ 0.9 %, but walls 1.0–2.9 % (the lightmap darker: adaptive texel placement interpolates
// with a bias; with --lattice 1 every wall is within 0.9 %) and the floor 1.0–2.0 % (the lightmap brighter:
// elements straddling the blocks' footprints average light and shadow, texels do not). Both are open work.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/gltf_fixture.h"

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
