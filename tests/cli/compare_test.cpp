// `hemibake compare` as users call it, on images the reference command renders: identical inputs give exactly 0,
// a known scale gives the known figure, maps and the HTML page are written, and mismatches are one-line errors.
// (Texel-for-texel figures per primitive are checked in baker_compare_test.cpp.)
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/gltf_fixture.h"

using hemibake::test::GltfFixture;
using hemibake::test::runHemibake;
using hemibake::test::TempDir;
namespace fs = std::filesystem;

namespace {

// An open room: floor (ρ 0.5) and a ceiling emitter of radiance `emission`, seen from above at an angle.
std::string writeRoom(const TempDir& dir, const std::string& name, double emission) {
    GltfFixture g;
    const int white = g.addMaterial({{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1.0}}, {"metallicFactor", 0.0}}}});
    const int light = g.addMaterial({{"pbrMetallicRoughness", {{"baseColorFactor", {0.0, 0.0, 0.0, 1.0}}, {"metallicFactor", 0.0}}},
                                     {"emissiveFactor", {1.0, 1.0, 1.0}},
                                     {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", emission}}}}}});
    g.json()["extensionsUsed"] = {"KHR_materials_emissive_strength"};
    const int floorPos = g.addPositions({-1, 0, -1, -1, 0, 1, 1, 0, 1, 1, 0, -1});
    g.addNode({{"name", "floor"}, {"mesh", g.addMesh(floorPos, g.addIndicesU16({0, 1, 2, 0, 2, 3}), white)}});
    const int lightPos = g.addPositions({-0.5f, 1, -0.5f, 0.5f, 1, -0.5f, 0.5f, 1, 0.5f, -0.5f, 1, 0.5f});
    g.addNode({{"name", "light"}, {"mesh", g.addMesh(lightPos, g.addIndicesU16({0, 1, 2, 0, 2, 3}), light)}});
    return g.writeGltf(dir, name);
}

std::string render(const TempDir& dir, const std::string& scene, const std::string& name, int width = 32,
                   const std::string& seed = "1") {
    const std::string image = dir.file(name);
    const auto r = runHemibake({"reference", scene, "--camera-pos", "0,0.8,1.5", "--camera-dir", "0,-0.5,-1", "--width",
                                std::to_string(width), "--height", "24", "--spp", "8", "--seed", seed, "-o", image});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return image;
}

nlohmann::json compareJson(const std::vector<std::string>& args) {
    std::vector<std::string> all = {"compare"};
    all.insert(all.end(), args.begin(), args.end());
    all.push_back("--json");
    const auto r = runHemibake(all);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return r.exitCode == 0 ? nlohmann::json::parse(r.out) : nlohmann::json();
}

std::string readText(const fs::path& path) {
    std::ostringstream s;
    s << std::ifstream(path).rdbuf();
    return s.str();
}

}  // namespace

TEST(CliCompare, IdenticalImagesHaveZeroError) {
    TempDir dir;
    const std::string image = render(dir, writeRoom(dir, "room", 1.0), "a.exr");
    const nlohmann::json j = compareJson({image, image});
    EXPECT_EQ(j["format"], "hemibake-compare/1");
    EXPECT_EQ(j["mode"], "images");
    EXPECT_EQ(j["global"]["texels"], 32 * 24);
    for (const char* figure : {"meanRelativeError", "p95RelativeError", "maxRelativeError", "rmse", "relativeMse"})
        EXPECT_EQ(j["global"][figure].get<double>(), 0.0) << figure;
    EXPECT_GT(j["global"]["meanB"][0].get<double>(), 0.0);
}

TEST(CliCompare, ScaledEmissionGivesTheKnownError) {
    // Radiance is linear in emission and the same seed traces the same paths: the second image is 1.1 × the first
    // (to float rounding), so A vs B has relative error 1/11 everywhere except where both are black.
    TempDir dir;
    const std::string a = render(dir, writeRoom(dir, "room", 1.0), "a.exr");
    const std::string b = render(dir, writeRoom(dir, "brighter", 1.1), "b.exr");
    const nlohmann::json j = compareJson({a, b});
    const double meanB = j["global"]["meanB"][0].get<double>(), meanA = j["global"]["meanA"][0].get<double>();
    EXPECT_NEAR(meanB / meanA, 1.1, 1e-5);
    EXPECT_NEAR(j["global"]["maxRelativeError"].get<double>(), 1.0 / 11.0, 1e-5);
    EXPECT_NEAR(j["global"]["p95RelativeError"].get<double>(), 1.0 / 11.0, 1e-5);
    EXPECT_GT(j["global"]["meanRelativeError"].get<double>(), 0.5 / 11.0);  // black sky pixels count as 0
    EXPECT_LE(j["global"]["meanRelativeError"].get<double>(), 1.0 / 11.0 + 1e-5);
    EXPECT_NEAR(j["global"]["meanSignedRelativeError"].get<double>(), -j["global"]["meanRelativeError"].get<double>(), 1e-9);
    const nlohmann::json swapped = compareJson({b, a});
    EXPECT_NEAR(swapped["global"]["maxRelativeError"].get<double>(), 0.1, 1e-5);
}

TEST(CliCompare, WritesMapsAndASelfContainedPage) {
    TempDir dir;
    const std::string scene = writeRoom(dir, "room", 1.0);
    const std::string a = render(dir, scene, "a.exr", 32, "1"), b = render(dir, scene, "b.exr", 32, "2");
    const std::string html = dir.file("report.html"), prefix = dir.file("maps/err");
    const auto r = runHemibake({"compare", a, b, "--html", html, "--map", prefix, "--map-range", "0.5"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("global"), std::string::npos) << r.out;  // the table
    EXPECT_TRUE(fs::exists(prefix + ".exr"));
    std::ifstream png(prefix + ".png", std::ios::binary);
    char magic[4] = {};
    png.read(magic, 4);
    EXPECT_EQ(std::string(magic + 1, 3), "PNG");
    const std::string page = readText(html);
    std::size_t embedded = 0;
    for (std::size_t at = page.find("data:image/png;base64,"); at != std::string::npos; at = page.find("data:image/png;base64,", at + 1))
        ++embedded;
    EXPECT_EQ(embedded, 3u);
    EXPECT_NE(page.find("±50%"), std::string::npos);
    // The error map of two different seeds shows the difference; the map of one image against itself is 0.
    const nlohmann::json same = compareJson({a, a, "--map", dir.file("same")});
    EXPECT_EQ(same["maps"][0]["exr"], dir.file("same") + ".exr");
    const nlohmann::json zero = compareJson({dir.file("same.exr"), dir.file("same.exr")});
    EXPECT_EQ(zero["global"]["meanA"], nlohmann::json({0.0, 0.0, 0.0}));
}

TEST(CliCompare, MismatchesAreOneLineErrors) {
    TempDir dir;
    const std::string scene = writeRoom(dir, "room", 1.0);
    const std::string a = render(dir, scene, "a.exr", 32), c = render(dir, scene, "c.exr", 40);
    auto expectError = [](const std::vector<std::string>& args, const std::string& named) {
        const auto r = runHemibake(args);
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_TRUE(r.out.empty()) << r.out;
    };
    expectError({"compare", a, c}, "c.exr");                     // sizes differ
    expectError({"compare", a, dir.path().string()}, dir.path().string());  // an image and a directory
    expectError({"compare", a, dir.file("missing.exr")}, "missing.exr");
    expectError({"compare", dir.path().string(), dir.path().string()}, "bake.json");  // not a bake
    EXPECT_EQ(runHemibake({"compare", a}).exitCode, 2);
    EXPECT_EQ(runHemibake({"compare", a, a, "--map-range", "0"}).exitCode, 2);
}
