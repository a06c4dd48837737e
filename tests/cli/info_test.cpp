// The hemibake binary as users call it: exit codes, one-line errors on stderr, `info --json` figures.
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/gltf_fixture.h"

using hemibake::test::runHemibake;
using hemibake::test::TempDir;

namespace {

std::size_t lineCount(const std::string& s) {
    std::size_t n = 0;
    for (char c : s) n += c == '\n';
    return n + (!s.empty() && s.back() != '\n');
}

}  // namespace

TEST(CliInfo, CornellBoxJson) {
    const auto r = runHemibake({"info", hemibake::test::sharedScene("cornell_box.gltf"), "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["format"], "hemibake-info/1");
    EXPECT_EQ(j["meshNodes"], 8);
    EXPECT_EQ(j["cameras"].size(), 1u);
    EXPECT_EQ(j["emitters"].size(), 1u);
    const double area = 0.13 * 0.105;  // GROUND_TRUTH §5 light, 130 × 105 mm
    const double expected[3] = {M_PI * 17.0 * area, M_PI * 12.0 * area, M_PI * 4.0 * area};
    for (int c = 0; c < 3; ++c) {
        const double w = j["emittedPowerWatts"][std::size_t(c)].get<double>();
        EXPECT_NEAR(w, expected[c], 1e-3 * expected[c]) << "channel " << c;  // acceptance: within 0.1%
    }
    EXPECT_GT(j["subdivision"]["elements"].get<int>(), j["subdivision"]["patches"].get<int>());
}

TEST(CliInfo, TextOutputNamesTheEssentials) {
    const auto r = runHemibake({"info", hemibake::test::sharedScene("cornell_box.gltf"), "--patch-size", "0.1"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* word : {"triangles", "emitters", "cornell_camera", "patches", "elements"})
        EXPECT_NE(r.out.find(word), std::string::npos) << word;
}

TEST(CliInfo, BadInputExitsOneWithOneLine) {
    TempDir dir;
    std::ofstream(dir.file("junk.gltf")) << "not json at all";
    for (const std::string& path : {dir.file("missing.gltf"), dir.file("junk.gltf")}) {
        const auto r = runHemibake({"info", path});
        EXPECT_EQ(r.exitCode, 1) << path;
        EXPECT_EQ(lineCount(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
        EXPECT_TRUE(r.out.empty());
    }
}

TEST(CliInfo, BadCommandLineExitsTwo) {
    EXPECT_EQ(runHemibake({}).exitCode, 2);
    EXPECT_EQ(runHemibake({"info"}).exitCode, 2);
    EXPECT_EQ(runHemibake({"info", "x.gltf", "--patch-size", "-1"}).exitCode, 2);
    EXPECT_EQ(runHemibake({"no-such-command"}).exitCode, 2);
}

TEST(CliInfo, HelpExplainsKnobs) {
    const auto r = runHemibake({"info", "--help"});
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_NE(r.out.find("--patch-size"), std::string::npos);
    EXPECT_NE(r.out.find("metres"), std::string::npos);
}
