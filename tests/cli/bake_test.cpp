// `hemibake bake` as users call it: the bake.json contract, convergence history, exit codes, no partial output.
#include <chrono>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/gltf_fixture.h"

using hemibake::test::runHemibake;
using hemibake::test::TempDir;

TEST(CliBake, CornellWritesReportWithConvergenceHistory) {
    TempDir dir;
    const std::string out = dir.file("out");
    const auto started = std::chrono::steady_clock::now();
    const auto r = runHemibake({"bake", hemibake::test::sharedScene("cornell_box.gltf"), "-o", out, "--preset", "draft",
                                "--hemicube-res", "32", "--epsilon", "0.02", "--solver", "shoot", "--progress",
                                "--emitters", "hemicube"});  // emitters shoot: the history starts at all power unshot
    const double processSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("solved: converged"), std::string::npos) << r.err;  // progress was reported
    std::ifstream in(out + "/bake.json");
    ASSERT_TRUE(in.good());
    const auto j = nlohmann::json::parse(in);
    EXPECT_EQ(j["format"], "hemibake-bake/1");
    EXPECT_EQ(j["settings"]["hemicubeResolution"], 32);
    EXPECT_EQ(j["settings"]["preset"], "draft");
    EXPECT_EQ(j["convergence"]["stopReason"], "converged");
    EXPECT_LE(j["convergence"]["unshotFraction"].get<double>(), 0.02);
    const auto& history = j["convergence"]["history"];
    ASSERT_GE(history.size(), 3u);
    // Nothing shot yet; the queue total (pairwise) and the injected total (running) round differently by ulps.
    EXPECT_NEAR(history.front()["unshotFraction"].get<double>(), 1.0, 1e-12);
    EXPECT_LE(history.back()["unshotFraction"].get<double>(), 0.02);
    for (std::size_t i = 1; i < history.size(); ++i)
        EXPECT_GE(history[i]["shots"].get<double>(), history[i - 1]["shots"].get<double>());
    // Power ledger: every emitted watt is absorbed, escaped through the open front, or still unshot.
    for (int c = 0; c < 3; ++c) {
        const double in_ = j["power"]["emittedW"][c].get<double>() + j["power"]["directW"][c].get<double>();
        const double out_ = j["power"]["absorbedW"][c].get<double>() + j["power"]["escapedW"][c].get<double>() +
                            j["power"]["backfaceW"][c].get<double>() + j["power"]["unshotW"][c].get<double>();
        EXPECT_NEAR(out_, in_, 1e-6 * in_) << "channel " << c;
    }
    for (const char* stage : {"load", "setup", "solve", "unwrap", "lightmaps", "write", "total"})
        EXPECT_TRUE(j["timings"].contains(stage)) << stage;
    // Stages do not overlap and total is the wall time: the stages add up to at most the total, which the process's
    // own wall time (measured here, from outside) bounds. The solve's breakdown lives beside its history.
    double stages = 0.0;
    for (const auto& [stage, seconds] : j["timings"].items())
        if (stage != "total") stages += seconds.get<double>();
    EXPECT_LE(stages, j["timings"]["total"].get<double>() + 1e-3);
    EXPECT_LE(j["timings"]["total"].get<double>(), processSeconds);
    const auto& solveSeconds = j["convergence"]["seconds"];
    EXPECT_LE(solveSeconds["direct"].get<double>() + solveSeconds["shoot"].get<double>() + solveSeconds["gather"].get<double>(),
              j["timings"]["solve"].get<double>() + 1e-3);
    EXPECT_GT(j["peakMemoryMiB"].get<double>(), 0.0);
}

TEST(CliBake, BadSceneLeavesNoOutput) {
    TempDir dir;
    std::ofstream(dir.file("bad.gltf")) << "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[]}]}";
    const std::string out = dir.file("out");
    const auto r = runHemibake({"bake", dir.file("bad.gltf"), "-o", out});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("bad.gltf"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out + "/bake.json"));
}

TEST(CliBake, BadKnobsExitTwo) {
    const std::string scene = hemibake::test::sharedScene("cornell_box.gltf");
    EXPECT_EQ(runHemibake({"bake", scene}).exitCode, 2);                                  // no -o
    EXPECT_EQ(runHemibake({"bake", scene, "-o", "/tmp/x", "--preset", "fast"}).exitCode, 2);
    EXPECT_EQ(runHemibake({"bake", scene, "-o", "/tmp/x", "--sky", "1,2"}).exitCode, 2);
    EXPECT_EQ(runHemibake({"bake", scene, "-o", "/tmp/x", "--solver", "magic"}).exitCode, 2);
}

TEST(CliBake, HelpExplainsEveryKnob) {
    const auto r = runHemibake({"bake", "--help"});
    EXPECT_EQ(r.exitCode, 0);
    for (const char* knob : {"--preset", "--patch-size", "--element-size", "--hemicube-res", "--epsilon", "--solver",
                             "--gather-sweeps", "--sky", "--max-time", "--threads", "draft", "ultra"})
        EXPECT_NE(r.out.find(knob), std::string::npos) << knob;
}

// Input the loader had to correct (CONVENTIONS: reflectance clamped to [0, 0.999] "with a warning") is reported by
// the bake itself, on stderr and in bake.json, not only by `info`.
TEST(CliBake, LoaderWarningsReachTheUser) {
    TempDir dir;
    hemibake::test::GltfFixture g;
    const int hot = g.addMaterial({{"name", "too_bright"},
                                   {"pbrMetallicRoughness", {{"baseColorFactor", {1.5, 0.5, 0.5, 1.0}}, {"metallicFactor", 0.0}}}});
    const int light = g.addMaterial({{"pbrMetallicRoughness", {{"baseColorFactor", {0.0, 0.0, 0.0, 1.0}}, {"metallicFactor", 0.0}}},
                                     {"emissiveFactor", {1.0, 1.0, 1.0}}});
    const int floorPos = g.addPositions({-1, 0, -1, -1, 0, 1, 1, 0, 1, 1, 0, -1});
    g.addNode({{"name", "floor"}, {"mesh", g.addMesh(floorPos, g.addIndicesU16({0, 1, 2, 0, 2, 3}), hot)}});
    const int lightPos = g.addPositions({-0.5f, 1, -0.5f, 0.5f, 1, -0.5f, 0.5f, 1, 0.5f, -0.5f, 1, 0.5f});
    g.addNode({{"name", "light"}, {"mesh", g.addMesh(lightPos, g.addIndicesU16({0, 1, 2, 0, 2, 3}), light)}});
    const std::string scene = g.writeGltf(dir, "bright.gltf");
    const std::string out = dir.file("out");
    const auto r = runHemibake({"bake", scene, "-o", out, "--preset", "draft"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("warning: " + scene + ": material 'too_bright'"), std::string::npos) << r.err;
    std::ifstream in(out + "/bake.json");
    const auto j = nlohmann::json::parse(in);
    ASSERT_EQ(j["warnings"].size(), 1u) << j["warnings"].dump();
    EXPECT_NE(j["warnings"][0].get<std::string>().find("clamped"), std::string::npos);
}
