// `hemibake reference` as users call it: the camera furnace (radiance L_e/(1−ρ) everywhere), files written, spp
// and time limits honoured, command-line errors, and texel mode on a real Cornell box bake. The EXR contents
// are read back through `hemibake compare` (this suite has no image library of its own).
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/gltf_fixture.h"
#include "support/gltf_validator.h"

using hemibake::test::GltfFixture;
using hemibake::test::runHemibake;
using hemibake::test::TempDir;
namespace fs = std::filesystem;

namespace {

constexpr float kReflectance = hemibake::test::kFurnaceReflectance;
const double* const kEmitted = hemibake::test::kFurnaceEmitted;

std::string writeFurnace(const TempDir& dir) { return hemibake::test::furnaceFixture().writeGltf(dir, "furnace"); }

nlohmann::json parseJson(const std::string& text) {
    try {
        return nlohmann::json::parse(text);
    } catch (const std::exception& e) {
        ADD_FAILURE() << "not JSON: " << e.what() << "\n" << text;
        return {};
    }
}

bool isPng(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    char magic[8] = {};
    in.read(magic, 8);
    return in && std::string(magic + 1, 3) == "PNG";
}

}  // namespace

TEST(CliReference, FurnaceCameraSeesEmissionOverOneMinusReflectance) {
    TempDir dir;
    const std::string scene = writeFurnace(dir);
    const std::string image = dir.file("furnace.exr");
    const auto r = runHemibake({"reference", scene, "--camera-pos", "0.5,0.5,0.5", "--camera-dir", "0.3,0.2,1", "--width", "24",
                                "--height", "16", "--spp", "64", "-o", image, "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json j = parseJson(r.out);
    EXPECT_EQ(j["format"], "hemibake-reference/1");
    EXPECT_EQ(j["mode"], "camera");
    EXPECT_EQ(j["spp"], 64);
    EXPECT_FALSE(j["timeLimited"].get<bool>());
    EXPECT_NE(r.err.find("64 spp"), std::string::npos) << r.err;  // the spp reached, on stderr
    for (int c = 0; c < 3; ++c) {
        const double expected = kEmitted[c] / (1.0 - double(kReflectance));
        const double mean = j["imageMean"][c].get<double>(), sigma = j["imageMeanStandardError"][c].get<double>();
        EXPECT_GT(sigma, 0.0);
        EXPECT_LT(sigma, 0.01 * expected);
        EXPECT_LE(std::abs(mean - expected), 3.0 * sigma) << "channel " << c << ": " << mean << " ± " << sigma;
    }
    EXPECT_TRUE(fs::exists(dir.file("furnace.stderr.exr")));
    EXPECT_TRUE(isPng(dir.file("furnace.png")));
    // The EXR holds what the JSON reports: read back independently by compare.
    const auto back = runHemibake({"compare", image, image, "--json"});
    ASSERT_EQ(back.exitCode, 0) << back.err;
    const nlohmann::json c = parseJson(back.out);
    EXPECT_EQ(c["images"][0]["width"], 24);
    EXPECT_EQ(c["images"][0]["height"], 16);
    for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(c["global"]["meanA"][ch].get<double>(), j["imageMean"][ch].get<double>(), 1e-6 * j["imageMean"][ch].get<double>());
}

TEST(CliReference, NamedCameraAndReproducibleSeeds) {
    TempDir dir;
    const std::string scene = writeFurnace(dir);
    auto render = [&](const std::string& name, const std::string& seed) {
        const auto r = runHemibake({"reference", scene, "--camera", "inside", "--width", "24", "--spp", "8", "--seed", seed,
                                    "-o", dir.file(name), "--json"});
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return parseJson(r.out);
    };
    const nlohmann::json a = render("a.exr", "1");
    EXPECT_EQ(a["camera"]["name"], "inside");
    EXPECT_EQ(a["height"], 16);  // 24 / aspect ratio 1.5
    EXPECT_NEAR(a["camera"]["yfovRadians"].get<double>(), 1.2, 1e-6);
    render("b.exr", "1");
    render("c.exr", "2");
    const auto same = runHemibake({"compare", dir.file("a.exr"), dir.file("b.exr"), "--json"});
    ASSERT_EQ(same.exitCode, 0) << same.err;
    EXPECT_EQ(parseJson(same.out)["global"]["maxRelativeError"].get<double>(), 0.0);
    const auto other = runHemibake({"compare", dir.file("a.exr"), dir.file("c.exr"), "--json"});
    ASSERT_EQ(other.exitCode, 0) << other.err;
    EXPECT_GT(parseJson(other.out)["global"]["meanRelativeError"].get<double>(), 0.0);
}

TEST(CliReference, TimeLimitStopsShortOfTheSpp) {
    TempDir dir;
    const std::string scene = writeFurnace(dir);
    const auto r = runHemibake({"reference", scene, "--camera", "inside", "--width", "48", "--spp", "16000000", "--time-limit",
                                "0.5", "-o", dir.file("t.exr"), "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json j = parseJson(r.out);
    EXPECT_TRUE(j["timeLimited"].get<bool>());
    EXPECT_EQ(j["targetSpp"].get<int>(), 16000000);
    EXPECT_EQ(j["settings"]["timeLimitSeconds"].get<double>(), 0.5);
    const double spp = j["spp"].get<double>(), seconds = j["seconds"].get<double>();
    EXPECT_GE(spp, 2.0);
    EXPECT_LT(spp, 16000000.0);
    // It stops only when one more sample per texel would not fit: the time used plus one sample's share reaches the
    // limit (how long that took is the machine's business, not this test's).
    EXPECT_GE(seconds * (1.0 + 1.0 / spp), 0.5);
    EXPECT_TRUE(fs::is_regular_file(dir.file("t.exr")));
    EXPECT_NE(r.err.find("stopped by the time limit"), std::string::npos) << r.err;
}

TEST(CliReference, BadCommandLinesAndInputs) {
    TempDir dir;
    const std::string scene = writeFurnace(dir);
    const std::string out = dir.file("x.exr");
    EXPECT_EQ(runHemibake({"reference", scene, "-o", out}).exitCode, 2);  // no camera
    EXPECT_EQ(runHemibake({"reference", scene, "--camera", "inside", "--camera-pos", "0,0,0", "--camera-dir", "0,0,1", "-o", out}).exitCode, 2);
    EXPECT_EQ(runHemibake({"reference", scene, "--camera-pos", "0,0,0", "-o", out}).exitCode, 2);  // no direction
    EXPECT_EQ(runHemibake({"reference", scene, "--camera-pos", "0,0,0", "--camera-dir", "0,1,0", "-o", out}).exitCode, 2);  // up ∥ dir
    EXPECT_EQ(runHemibake({"reference", scene, "--camera", "inside", "-o", dir.file("x.png")}).exitCode, 2);
    EXPECT_EQ(runHemibake({"reference", scene, "--texels", dir.path().string(), "-o", dir.file("ref")}).exitCode, 2);
    EXPECT_EQ(runHemibake({"reference", scene, "--camera", "inside", "--spp", "0", "-o", out}).exitCode, 2);

    const auto unknown = runHemibake({"reference", scene, "--camera", "outside", "-o", out});
    EXPECT_EQ(unknown.exitCode, 1);
    EXPECT_NE(unknown.err.find("furnace.gltf"), std::string::npos) << unknown.err;
    EXPECT_NE(unknown.err.find("inside"), std::string::npos) << unknown.err;  // lists the cameras there are
    EXPECT_EQ(std::count(unknown.err.begin(), unknown.err.end(), '\n'), 1) << unknown.err;
    const auto notBake = runHemibake({"reference", "--texels", dir.path().string(), "-o", dir.file("ref")});
    EXPECT_EQ(notBake.exitCode, 1);
    EXPECT_NE(notBake.err.find("bake.json"), std::string::npos) << notBake.err;
    EXPECT_FALSE(fs::exists(out));
}

// Texel mode on a real bake: the Cornell box at a quick setting, the reference at low spp.
TEST(CliReference, CornellTexelsFollowTheBakeLayout) {
    TempDir dir;
    const std::string out = dir.file("bake"), ref = dir.file("ref");
    const auto bake = runHemibake({"bake", hemibake::test::sharedScene("cornell_box.gltf"), "-o", out, "--preset", "draft",
                                   "--hemicube-res", "16", "--epsilon", "0.2", "--solver", "shoot", "--gather-sweeps", "0"});
    ASSERT_EQ(bake.exitCode, 0) << bake.err;
    EXPECT_GLBS_VALID(out);
    const nlohmann::json bakeJson = nlohmann::json::parse(std::ifstream(out + "/bake.json"));
    ASSERT_TRUE(bakeJson.contains("lightmap")) << "the bake wrote no lightmaps";

    const auto r = runHemibake({"reference", "--texels", out, "-o", ref, "--spp", "16"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.out, ref + "/reference.json\n");
    const nlohmann::json j = nlohmann::json::parse(std::ifstream(ref + "/reference.json"));
    EXPECT_EQ(j["format"], "hemibake-reference/1");
    EXPECT_EQ(j["spp"], 16);
    EXPECT_EQ(j["primitives"], bakeJson["primitives"]);
    EXPECT_EQ(j["lightmap"]["files"], bakeJson["lightmap"]["files"]);
    EXPECT_EQ(j["texels"], bakeJson["lightmap"]["texels"]);

    for (std::size_t a = 0; a < bakeJson["lightmap"]["files"].size(); ++a) {
        const std::string file = bakeJson["lightmap"]["files"][a];
        EXPECT_TRUE(fs::exists(ref + "/" + fs::path(file).replace_extension(".stderr.exr").string()));
        // Same size: compare of the two EXRs as images fails on any size mismatch.
        const auto sizes = runHemibake({"compare", out + "/" + file, ref + "/" + file, "--json"});
        ASSERT_EQ(sizes.exitCode, 0) << sizes.err;
        EXPECT_EQ(parseJson(sizes.out)["images"][0]["width"], bakeJson["lightmap"]["atlases"][a]["size"]);
    }
    // Texel for texel: every primitive has texels, and the two agree on each surface's mean to within the
    // noise of 16 spp and the quick bake's error.
    const auto c = runHemibake({"compare", out, ref, "--json"});
    ASSERT_EQ(c.exitCode, 0) << c.err;
    const nlohmann::json cj = parseJson(c.out);
    EXPECT_TRUE(cj["warnings"].empty()) << cj["warnings"].dump();
    ASSERT_EQ(cj["primitives"].size(), bakeJson["primitives"].size());
    for (const auto& p : cj["primitives"]) {
        EXPECT_GT(p["errors"]["texels"].get<int>(), 50) << p["node"];
        const double a = p["errors"]["meanA"][0].get<double>(), b = p["errors"]["meanB"][0].get<double>();
        EXPECT_NEAR(a / b, 1.0, 0.3) << p["node"];
    }
    EXPECT_LT(cj["images"][0]["insideGeometryTexels"].get<int>(), cj["global"]["texels"].get<int>() / 10);
}
