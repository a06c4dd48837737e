// `hemibake bake` as users call it: the bake.json contract, convergence history, exit codes, no partial output.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/gltf_fixture.h"
#include "support/gltf_validator.h"
#include "support/hostile_gltf.h"

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
    // The local phase reports its own figure (history and progress line; the CLI throttles the latter): the last
    // record's is the bound the solve stopped on (≤ ε), the same as convergence.localBound.max.
    ASSERT_TRUE(history.back().contains("localBound")) << history.back();
    EXPECT_LE(history.back()["localBound"].get<double>(), 0.02);
    EXPECT_DOUBLE_EQ(history.back()["localBound"].get<double>(), j["convergence"]["localBound"]["max"].get<double>());
    EXPECT_FALSE(history.front().contains("localBound"));
    // The local rounds count up to the solve's; the last record is the bound it stopped on, where no lit patch is left
    // unshot and nothing is left to shoot.
    ASSERT_TRUE(history.back().contains("localRound")) << history.back();
    std::uint64_t lastRound = 0;
    for (const auto& record : history)
        if (record.contains("localRound")) {
            EXPECT_GE(record["localRound"]["round"].get<std::uint64_t>(), std::max<std::uint64_t>(lastRound, 1));
            lastRound = record["localRound"]["round"].get<std::uint64_t>();
        }
    EXPECT_EQ(lastRound, j["convergence"]["localRounds"].get<std::uint64_t>());
    EXPECT_EQ(history.back()["localRound"]["neverShotPatches"], 0);
    EXPECT_EQ(history.back()["localRound"]["patches"], 0);
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
    EXPECT_GT(solveSeconds["prepare"].get<double>(), 0.0);  // subdividing is never free
    EXPECT_LE(solveSeconds["prepare"].get<double>() + solveSeconds["direct"].get<double>() +
                  solveSeconds["shoot"].get<double>() + solveSeconds["gather"].get<double>(),
              j["timings"]["solve"].get<double>() + 1e-3);
    // The lightmap stage's parts, likewise: none negative, together within the stage; the gathers are never free.
    const auto& lightmapSeconds = j["lightmap"]["seconds"];
    double parts = 0.0;
    for (const char* part : {"setup", "direct", "texelLight", "gather", "refill", "gaps", "dilateAndSeams"}) {
        ASSERT_TRUE(lightmapSeconds.contains(part)) << part;
        EXPECT_GE(lightmapSeconds[part].get<double>(), 0.0) << part;
        parts += lightmapSeconds[part].get<double>();
    }
    EXPECT_GT(lightmapSeconds["gather"].get<double>(), 0.0);
    EXPECT_LE(parts, j["timings"]["lightmaps"].get<double>() + 1e-3);
    EXPECT_GT(j["peakMemoryMiB"].get<double>(), 0.0);
    EXPECT_GLBS_VALID(out);
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
                             "--gather-sweeps", "--sky", "--max-time", "--threads", "draft", "ultra", "--final-gather",
                             "--gather-rays", "--shoot-rows", "--row-rays", "--max-ray-traced-emitters"})
        EXPECT_NE(r.out.find(knob), std::string::npos) << knob;
}

// The ray-traced emitters' limit is a knob: the Cornell box's lamp is two input triangles, so a limit of 1 sends its
// light through the shooter, with the warning and the report saying so, and the default traces it.
TEST(CliBake, EmitterLimitIsAKnob) {
    TempDir dir;
    for (const bool limited : {false, true}) {
        const std::string out = dir.file(limited ? "limited" : "default");
        std::vector<std::string> args = {"bake", hemibake::test::sharedScene("cornell_box.gltf"), "-o", out, "--preset",
                                         "draft", "--no-preview"};
        if (limited) args.insert(args.end(), {"--max-ray-traced-emitters", "1"});
        const auto r = runHemibake(args);
        ASSERT_EQ(r.exitCode, 0) << r.err;
        std::ifstream in(out + "/bake.json");
        const auto j = nlohmann::json::parse(in);
        EXPECT_EQ(j["settings"]["maxRayTracedEmitters"], limited ? 1 : 4096);
        EXPECT_EQ(j["convergence"]["emittersByRays"], !limited);
        EXPECT_EQ(r.err.find("input triangles") != std::string::npos, limited) << r.err;
    }
    EXPECT_EQ(runHemibake({"bake", hemibake::test::sharedScene("cornell_box.gltf"), "-o", dir.file("x"),
                           "--max-ray-traced-emitters", "-1"}).exitCode, 2);
}

// The CLI restarts itself with glibc's heap in transparent huge pages and one arena (cli/huge_page_heap.h); bake.json
// says whether it runs so. A GLIBC_TUNABLES that names either tunable is the user's choice and kept (hugetlb=0 turns it
// off); other tunables stay beside them. The light baked is the same texel for texel every way.
TEST(CliBake, HeapInHugePagesUnlessTheUserSaysOtherwise) {
    std::string thp;
    std::getline(std::ifstream("/sys/kernel/mm/transparent_hugepage/enabled"), thp);
    const bool kernelOn = thp.find("[always]") != std::string::npos || thp.find("[madvise]") != std::string::npos;
    const char* saved = std::getenv("GLIBC_TUNABLES");
    const std::string savedValue = saved ? saved : "";
    struct Case {
        const char* tunables;  // GLIBC_TUNABLES for the run; null: unset
        bool hugePages;
    };
    // Huge pages for the whole heap take glibc.malloc.hugetlb=1 and one arena (glibc madvises only its main heap): the
    // restart adds both, and keeps what the user set (arena_max=4 leaves threads' arenas in small pages, and says so).
    const Case cases[] = {{nullptr, kernelOn},
                          {"glibc.malloc.hugetlb=0", false},
                          {"glibc.malloc.arena_max=4", false},
                          {"glibc.malloc.hugetlb=1", false},
                          {"glibc.malloc.arena_max=1:glibc.malloc.hugetlb=1", kernelOn},
                          {"glibc.malloc.tcache_count=4", kernelOn}};
    TempDir dir;
    for (std::size_t k = 0; k < std::size(cases); ++k) {
        if (cases[k].tunables) setenv("GLIBC_TUNABLES", cases[k].tunables, 1);
        else unsetenv("GLIBC_TUNABLES");
        const auto r = runHemibake({"bake", hemibake::test::sharedScene("cornell_box.gltf"), "-o", dir.file("bake" + std::to_string(k)),
                                    "--preset", "draft", "--no-preview"});
        if (saved) setenv("GLIBC_TUNABLES", savedValue.c_str(), 1);
        else unsetenv("GLIBC_TUNABLES");
        ASSERT_EQ(r.exitCode, 0) << r.err;
        std::ifstream in(dir.file("bake" + std::to_string(k)) + "/bake.json");
        const auto j = nlohmann::json::parse(in);
        EXPECT_EQ(j["hugePageHeap"], cases[k].hugePages) << (cases[k].tunables ? cases[k].tunables : "(unset)") << ", kernel: " << thp;
    }
    for (std::size_t k = 1; k < std::size(cases); ++k) {  // texel for texel (the EXR files differ in their creation time)
        const std::string other = "bake" + std::to_string(k);
        const auto r = runHemibake({"compare", dir.file("bake0"), dir.file(other), "--json"});
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const auto j = nlohmann::json::parse(r.out);
        EXPECT_GT(j["global"]["texels"].get<int>(), 1000);
        EXPECT_EQ(j["global"]["maxRelativeError"].get<double>(), 0.0) << other;
    }
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
    // The input's baseColorFactor 1.5 is invalid glTF, and the output keeps the input's material as it is.
    EXPECT_GLBS_VALID_BUT_FOR_INPUT(out, scene);
}

// ---- issue 17: input that passes the loader's parser, baked end to end ----

namespace {

// The quickest bake that still runs every stage.
std::vector<std::string> quickBake(const std::string& scene, const std::string& out, std::vector<std::string> extra = {}) {
    std::vector<std::string> args = {"bake", scene, "-o", out, "--preset", "draft", "--hemicube-res", "16", "--threads", "1"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
}

nlohmann::json readBakeJson(const std::string& out) {
    std::ifstream in(out + "/bake.json");
    return nlohmann::json::parse(in);
}

}  // namespace

// Nested nodes used to crash the bake with a segfault (exit 139): the recursive node walk overflowed the stack from
// about 4,700 levels (Release). 5,000 levels bake. (The loader test walks 20,000; here the Khronos validator must
// read the output too, and its time grows with the cube of the depth: 5 s at 5,000 levels, 4.6 min at 20,000.)
TEST(CliBakeExtremes, DeepHierarchyBakes) {
    TempDir dir;
    const std::string scene = hemibake::test::deepHierarchyFixture(5000).writeGltf(dir, "deep");
    const std::string out = dir.file("out");
    const auto r = runHemibake(quickBake(scene, out));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json j = readBakeJson(out);
    ASSERT_EQ(j["primitives"].size(), 1u);
    EXPECT_EQ(j["primitives"][0]["node"], "leaf");
    EXPECT_GLBS_VALID(out);
}

// A node with an all-zero matrix used to vanish without a word. The bake names it in a warning (stderr, bake.json)
// and bakes the rest. The same for a zero scale (valid glTF, how some exporters hide objects).
TEST(CliBakeExtremes, SingularNodeIsNamedAndTheRestBakes) {
    for (const bool zeroMatrix : {true, false}) {
        SCOPED_TRACE(zeroMatrix ? "zero matrix" : "zero scale");
        TempDir dir;
        hemibake::test::GltfFixture g = hemibake::test::singularNodeFixture(true);
        if (!zeroMatrix) {
            g.json()["nodes"][0].erase("matrix");
            g.json()["nodes"][0]["scale"] = {0.0, 0.0, 0.0};
        }
        const std::string scene = g.writeGltf(dir, "singular");
        const std::string out = dir.file("out");
        const auto r = runHemibake(quickBake(scene, out));
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const std::string warning = "node 'flat' (node 0): its transform is singular and collapses 2 of its 2 triangles to zero area";
        EXPECT_NE(r.err.find("hemibake: warning: " + scene + ": " + warning), std::string::npos) << r.err;
        const nlohmann::json j = readBakeJson(out);
        ASSERT_EQ(j["warnings"].size(), 1u) << j["warnings"].dump();
        EXPECT_EQ(j["warnings"][0].get<std::string>().rfind(warning, 0), 0u) << j["warnings"].dump();
        ASSERT_EQ(j["primitives"].size(), 1u);
        EXPECT_EQ(j["primitives"][0]["node"], "floor");
        // A zero matrix is invalid glTF (NODE_MATRIX_NON_TRS) and the output keeps the input's nodes.
        if (zeroMatrix)
            EXPECT_GLBS_VALID_BUT_FOR_INPUT(out, scene);
        else
            EXPECT_GLBS_VALID(out);
    }
}

// Sparse accessors are read by the loader and written back by the glTF writer: the output validates and holds
// the substituted corners (the unit quad's area, not the base view's).
TEST(CliBakeExtremes, SparseAccessorSceneBakes) {
    TempDir dir;
    const std::string scene = hemibake::test::sparseQuadFixture().writeGltf(dir, "sparse");
    const std::string out = dir.file("out");
    const auto r = runHemibake(quickBake(scene, out));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto info = runHemibake({"info", out + "/sparse.glb", "--json"});
    ASSERT_EQ(info.exitCode, 0) << info.err;
    const nlohmann::json j = nlohmann::json::parse(info.out);
    EXPECT_NEAR(j["surfaceAreaM2"].get<double>(), 1.0, 1e-9);
    EXPECT_EQ(j["bounds"]["max"], nlohmann::json({1.0, 0.0, 1.0}));
    EXPECT_GLBS_VALID(out);
}

// The world-coordinate limit is no size judgement: a 100 km level and a 1 mm scene 6,400 km from the origin bake.
// (The 100 km floor at draft's default density is shrunk to one atlas: mesh_pack_test; here few texels keep it quick.)
TEST(CliBakeExtremes, HundredKilometreAndFarMillimetreScenesBake) {
    TempDir dir;
    struct Case {
        const char* name;
        double scale, offset;
        const char* texelsPerUnit;
    };
    for (const Case& c : {Case{"level", 1e5, 0.0, "0.0005"}, Case{"tiny", 1e-3, 6.4e6, "50000"}}) {
        SCOPED_TRACE(c.name);
        hemibake::test::GltfFixture g = hemibake::test::unitQuadFixture();
        g.json()["nodes"][0]["scale"] = {c.scale, c.scale, c.scale};
        g.json()["nodes"][0]["translation"] = {0.0, c.offset, 0.0};
        const std::string scene = g.writeGltf(dir, c.name);
        const std::string out = dir.file(std::string("out-") + c.name);
        const auto r = runHemibake(quickBake(scene, out, {"--texels-per-unit", c.texelsPerUnit, "--sky", "1,1,1"}));
        ASSERT_EQ(r.exitCode, 0) << r.err;
        EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
        const nlohmann::json j = readBakeJson(out);
        EXPECT_EQ(j["lightmap"]["texels"].get<int>(), 2500);  // 50 × 50 either way
        EXPECT_GLBS_VALID(out);
    }
}

// Presets size a scene by its largest island, not its whole box: two furnaces 2 km apart get the patches and texel
// density of one furnace (√3 m diagonal: draft's diagonal/6 patches, 64 texels along it), where sizing by the 2 km
// box gave 33 m patches and 8 texels/m. `info` reports the islands.
TEST(CliBake, FurnacesKilometresApartAreSizedAsOneFurnace) {
    TempDir dir;
    hemibake::test::GltfFixture g = hemibake::test::furnaceFixture();
    g.addNode({{"name", "far furnace"}, {"mesh", 0}, {"translation", {2000.0, 0.0, 0.0}}});
    const std::string scene = g.writeGltf(dir, "two-furnaces");
    const double furnaceDiagonalM = std::sqrt(3.0);

    const auto info = runHemibake({"info", scene, "--json"});
    ASSERT_EQ(info.exitCode, 0) << info.err;
    const nlohmann::json i = nlohmann::json::parse(info.out);
    EXPECT_EQ(i["islands"]["count"].get<int>(), 2);
    EXPECT_NEAR(i["islands"]["largestDiagonalM"].get<double>(), furnaceDiagonalM, 1e-6);

    const std::string out = dir.file("out");
    const auto r = runHemibake(quickBake(scene, out, {"--no-preview"}));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json j = readBakeJson(out);
    EXPECT_EQ(j["counts"]["islands"].get<int>(), 2);
    EXPECT_NEAR(j["settings"]["patchSizeM"].get<double>(), furnaceDiagonalM / 6.0, 1e-6);
    EXPECT_NEAR(j["settings"]["texelsPerUnit"].get<double>(), 64.0 / furnaceDiagonalM, 1e-4);
}
