// `hemibake sample-volume`: reads a volume written in the documented layout (docs/probes.md), by hand here, and
// prints E/π; exit codes for bad input (1) and a bad command line (2).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "support/gltf_fixture.h"

using hemibake::test::runHemibake;
using hemibake::test::TempDir;

namespace {

namespace fs = std::filesystem;

// 2×2×2 probes over [0,1]³, constant radiance L = 1 + x (grid index) in red, 0.5 in green: E/π = L for every
// normal. The probe at (1, 1, 1) is invalid and holds garbage that must not show. Each test writes into its own
// fresh folder: CTest runs the tests of this file in parallel.
fs::path writeVolume(const TempDir& temp) {
    const fs::path dir = temp.path();
    nlohmann::json j = {{"format", "hemibake-volume/1"},
                        {"min", {0, 0, 0}},
                        {"max", {1, 1, 1}},
                        {"resolution", {2, 2, 2}},
                        {"data", {{"file", "volume.bin"}, {"recordBytes", 112}}}};
    std::ofstream(dir / "volume.json") << j.dump();
    std::ofstream bin(dir / "volume.bin", std::ios::binary);
    const float l00 = 2.0f * std::sqrt(float(M_PI));
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 2; ++x) {
                const bool valid = !(x == 1 && y == 1 && z == 1);
                float sh[27] = {};
                sh[0] = valid ? l00 * (1.0f + float(x)) : 1000.0f;
                sh[1] = valid ? l00 * 0.5f : 1000.0f;
                bin.write(reinterpret_cast<const char*>(sh), sizeof sh);
                const std::uint32_t flag = valid ? 1 : 0;
                bin.write(reinterpret_cast<const char*>(&flag), sizeof flag);
            }
    return dir;
}

TEST(CliSampleVolume, PrintsInterpolatedIrradiance) {
    const TempDir temp;
    const fs::path dir = writeVolume(temp);
    const auto r = runHemibake({"sample-volume", dir.string(), "0.25", "0.5", "0.5", "0", "1", "0", "--json",
                             "--weighting", "trilinear"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    // Trilinear over the 7 valid probes: red = Σ w (1 + x) / Σ w with the (1,1,1) probe's weight removed.
    const double wMissing = 0.25 * 0.5 * 0.5;
    const double expected = (0.75 * 1.0 + 0.25 * 2.0 - wMissing * 2.0) / (1.0 - wMissing);
    EXPECT_NEAR(j["irradianceOverPi"][0].get<double>(), expected, 1e-5);
    EXPECT_NEAR(j["irradianceOverPi"][1].get<double>(), 0.5, 1e-5);
    EXPECT_EQ(j["probesUsed"].get<int>(), 7);

    const auto plain = runHemibake({"sample-volume", dir.string(), "0.25", "0.5", "0.5", "0", "1", "0", "--weighting", "naive"});
    ASSERT_EQ(plain.exitCode, 0) << plain.err;
    double red = 0, green = 0, blue = 0;
    ASSERT_EQ(std::sscanf(plain.out.c_str(), "%lf %lf %lf", &red, &green, &blue), 3) << plain.out;
    EXPECT_GT(red, 10.0);  // naive weighting uses the invalid probe (E/π ≈ 282 at weight 1/16): that is what it is for
}

TEST(CliSampleVolume, BadInputAndBadCommandLine) {
    const TempDir temp;
    const fs::path dir = writeVolume(temp);
    fs::resize_file(dir / "volume.bin", 100);
    const auto truncated = runHemibake({"sample-volume", dir.string(), "0", "0", "0", "0", "1", "0"});
    EXPECT_EQ(truncated.exitCode, 1);
    EXPECT_NE(truncated.err.find("volume.bin"), std::string::npos) << truncated.err;
    const auto missing = runHemibake({"sample-volume", (dir / "nothing").string(), "0", "0", "0", "0", "1", "0"});
    EXPECT_EQ(missing.exitCode, 1);
    EXPECT_EQ(runHemibake({"sample-volume", dir.string(), "0", "0", "0"}).exitCode, 2);
    EXPECT_EQ(runHemibake({"sample-volume", dir.string(), "0", "0", "0", "0", "0", "0"}).exitCode, 2);
}

}  // namespace
