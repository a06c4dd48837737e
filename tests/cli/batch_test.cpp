// `hemibake batch` end to end on tiny scenes (draft, small hemicubes, few texels): the summary, failure isolation,
// exit codes, resuming without re-baking, interrupts that leave no partial output, and shards that partition.
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <sys/wait.h>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/gltf_fixture.h"
#include "support/gltf_validator.h"
#include "support/spawn_hemibake.h"

namespace fs = std::filesystem;
using hemibake::test::runHemibake;
using hemibake::test::TempDir;

namespace {

// Settings that bake the Cornell box in a few seconds even under the sanitizers.
const nlohmann::json kTiny = {{"preset", "draft"}, {"hemicube-res", 16}, {"texels-per-unit", 4}, {"threads", 1}};

void copyCornell(const TempDir& dir) {
    for (const char* f : {"cornell_box.gltf", "cornell_box.bin"})
        fs::copy_file(fs::path(hemibake::test::sharedScene("cornell_box.gltf")).parent_path() / f, dir.path() / f);
}

void writeBroken(const TempDir& dir) {
    std::ofstream(dir.file("broken.gltf")) << R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[]}]})";
}

void writeJson(const std::string& path, const nlohmann::json& j) { std::ofstream(path) << j.dump(2); }

nlohmann::json readJson(const fs::path& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
}

std::map<std::string, nlohmann::json> byName(const nlohmann::json& summary) {
    std::map<std::string, nlohmann::json> m;
    for (const auto& s : summary["scenes"]) m[s["name"].get<std::string>()] = s;
    return m;
}

bool hasStagingLeft(const fs::path& dir) {
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.path().filename().string().find(".batch-") != std::string::npos) return true;
    return false;
}

}  // namespace

TEST(CliBatch, BakesGoodScenesReportsBrokenAndResumes) {
    TempDir dir;
    copyCornell(dir);
    writeBroken(dir);
    const std::string manifest = dir.file("levels.json");
    writeJson(manifest, {{"defaults", kTiny},
                         {"scenes", {{{"scene", "cornell_box.gltf"}, {"output", "out/a"}, {"name", "a"}},
                                     {{"scene", "broken.gltf"}, {"output", "out/broken"}},
                                     {{"scene", "cornell_box.gltf"}, {"output", "out/b"}, {"name", "b"},
                                      {"settings", {{"texels-per-unit", 6}}}}}}});
    auto r = runHemibake({"batch", manifest, "--progress"});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find("[3/3] b"), std::string::npos) << r.err;  // progress across scenes
    // The last line is the one-line failure report, naming the scene and the problem.
    const std::string last = r.err.substr(r.err.rfind('\n', r.err.size() - 2) + 1);
    EXPECT_NE(last.find("1 of 3 scenes failed"), std::string::npos) << last;
    EXPECT_NE(last.find("broken.gltf: the scene has no triangles"), std::string::npos) << last;
    EXPECT_EQ(r.out, dir.file("batch.json") + "\n");

    auto summary = readJson(dir.file("batch.json"));
    EXPECT_EQ(summary["format"], "hemibake-batch/1");
    auto scenes = byName(summary);
    ASSERT_EQ(scenes.size(), 3u);
    EXPECT_EQ(scenes["a"]["status"], "ok");
    EXPECT_EQ(scenes["b"]["status"], "ok");
    EXPECT_EQ(scenes["broken"]["status"], "failed");
    EXPECT_NE(scenes["broken"]["error"].get<std::string>().find("no triangles to bake"), std::string::npos);
    EXPECT_GT(scenes["a"]["peakMemoryMiB"].get<double>(), 0.0);
    EXPECT_GT(scenes["a"]["seconds"].get<double>(), 0.0);
    // Per-scene settings override the defaults.
    EXPECT_EQ(readJson(dir.path() / "out/a/bake.json")["lightmap"]["texelsPerUnit"].get<double>(), 4.0)
        << "bake.json layout changed?";
    EXPECT_EQ(readJson(dir.path() / "out/b/bake.json")["lightmap"]["texelsPerUnit"].get<double>(), 6.0);
    EXPECT_TRUE(fs::exists(dir.path() / "out/a/cornell_box.glb"));
    EXPECT_GLBS_VALID(dir.path() / "out/a");
    EXPECT_GLBS_VALID(dir.path() / "out/b");
    EXPECT_TRUE(fs::exists(dir.path() / "out/a/batch-stamp.json"));
    EXPECT_FALSE(fs::exists(dir.path() / "out/broken"));
    EXPECT_FALSE(hasStagingLeft(dir.path()));

    // Again: nothing good is re-baked; the broken scene is tried (and fails) again.
    const auto bakedAt = fs::last_write_time(dir.path() / "out/a/bake.json");
    r = runHemibake({"batch", manifest});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "without --progress, one line:\n" << r.err;
    scenes = byName(readJson(dir.file("batch.json")));
    EXPECT_EQ(scenes["a"]["status"], "skipped");
    EXPECT_EQ(scenes["a"]["reason"], "up to date");
    EXPECT_EQ(scenes["b"]["status"], "skipped");
    EXPECT_EQ(scenes["broken"]["status"], "failed");
    EXPECT_EQ(fs::last_write_time(dir.path() / "out/a/bake.json"), bakedAt);

    // Fix the broken scene and change one input byte of b's settings: exactly those two bake.
    fs::copy_file(dir.file("cornell_box.gltf"), dir.file("broken.gltf"), fs::copy_options::overwrite_existing);
    auto j = readJson(manifest);
    j["scenes"][2]["settings"]["texels-per-unit"] = 5;
    writeJson(manifest, j);
    r = runHemibake({"batch", manifest, "--summary", dir.file("second.json"), "--json"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out), readJson(dir.file("second.json")));  // --json: the summary on stdout
    scenes = byName(readJson(dir.file("second.json")));
    EXPECT_EQ(scenes["a"]["status"], "skipped");
    EXPECT_EQ(scenes["broken"]["status"], "ok");
    EXPECT_EQ(scenes["b"]["status"], "ok");
    for (const char* out : {"out/a", "out/b", "out/broken"}) EXPECT_GLBS_VALID(dir.path() / out);

    // Everything is up to date now: a plain run bakes nothing (a file left in an output survives), --force re-bakes
    // every scene (each output is replaced whole: the file is gone, bake.json and the stamp are new).
    std::ofstream(dir.path() / "out/a/left-behind.txt") << "not part of the bake";
    const auto stampedAt = fs::last_write_time(dir.path() / "out/a/batch-stamp.json");
    const auto reportedAt = fs::last_write_time(dir.path() / "out/a/bake.json");
    r = runHemibake({"batch", manifest, "--json"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    for (const auto& [name, s] : byName(nlohmann::json::parse(r.out))) EXPECT_EQ(s["status"], "skipped") << name;
    EXPECT_TRUE(fs::exists(dir.path() / "out/a/left-behind.txt"));
    EXPECT_EQ(fs::last_write_time(dir.path() / "out/a/bake.json"), reportedAt);
    r = runHemibake({"batch", manifest, "--force", "--json"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    const auto forced = nlohmann::json::parse(r.out);
    EXPECT_TRUE(forced["force"].get<bool>()) << forced.dump();
    scenes = byName(forced);
    ASSERT_EQ(scenes.size(), 3u);
    for (const auto& [name, s] : scenes) {
        EXPECT_EQ(s["status"], "ok") << name;
        EXPECT_FALSE(s.contains("reason")) << name << ": " << s.dump();
    }
    EXPECT_FALSE(fs::exists(dir.path() / "out/a/left-behind.txt")) << "--force did not replace out/a";
    EXPECT_NE(fs::last_write_time(dir.path() / "out/a/bake.json"), reportedAt);
    EXPECT_NE(fs::last_write_time(dir.path() / "out/a/batch-stamp.json"), stampedAt);
    EXPECT_FALSE(hasStagingLeft(dir.path()));
    for (const char* out : {"out/a", "out/b", "out/broken"}) EXPECT_GLBS_VALID(dir.path() / out);

    // An edited input (the shared .bin) invalidates every scene that reads it; --force rebakes regardless.
    std::ofstream(dir.file("cornell_box.bin"), std::ios::app) << '\0';
    r = runHemibake({"batch", manifest, "--dry-run", "--json"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    const auto plan = nlohmann::json::parse(r.out);
    for (const auto& s : plan["scenes"]) EXPECT_EQ(s["action"], "bake") << s.dump();
}

TEST(CliBatch, InterruptLeavesNoPartialOutputAndResumes) {
    TempDir dir;
    copyCornell(dir);
    const std::string level = std::string(HEMIBAKE_SOURCE_DIR) + "/examples/level_small.gltf";
    const std::string manifest = dir.file("m.json");
    // The second scene takes long enough (tens of seconds) to be interrupted part-way.
    writeJson(manifest, {{"defaults", kTiny},
                         {"scenes", {{{"scene", "cornell_box.gltf"}, {"output", "out/quick"}, {"name", "quick"}},
                                     {{"scene", level}, {"output", "out/level"}, {"name", "level"},
                                      {"settings", {{"preset", "medium"}, {"texels-per-unit", 16}}}}}}});
    const pid_t pid = hemibake::test::spawnHemibake({"batch", manifest}, dir.file("err"));
    ASSERT_GT(pid, 0);
    // Wait (by what is on disk, not by a clock) until the quick scene is in place and the level is being baked.
    bool staging = false;
    for (int i = 0; i < 6000 && !staging; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        if (fs::exists(dir.path() / "out/quick/batch-stamp.json") && fs::exists(dir.path() / "out"))
            for (const auto& e : fs::directory_iterator(dir.path() / "out"))
                staging |= e.path().filename().string().rfind(".level.batch-", 0) == 0;
        if (waitpid(pid, nullptr, WNOHANG) == pid) break;
    }
    ASSERT_TRUE(staging) << "the level's bake never started";
    ::kill(pid, SIGTERM);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1);
    std::ostringstream err;
    err << std::ifstream(dir.file("err")).rdbuf();
    EXPECT_NE(err.str().find("interrupted"), std::string::npos) << err.str();

    EXPECT_TRUE(fs::exists(dir.path() / "out/quick/bake.json"));
    EXPECT_GLBS_VALID(dir.path() / "out/quick");
    EXPECT_FALSE(fs::exists(dir.path() / "out/level")) << "partial output left behind";
    EXPECT_FALSE(hasStagingLeft(dir.path()));
    auto scenes = byName(readJson(dir.file("batch.json")));
    EXPECT_EQ(scenes["quick"]["status"], "ok");
    EXPECT_EQ(scenes["level"]["status"], "failed");
    EXPECT_EQ(scenes["level"]["error"], "interrupted");

    // Resuming would bake only what is missing.
    const auto r = runHemibake({"batch", manifest, "--dry-run", "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    std::map<std::string, std::string> action;
    const auto plan = nlohmann::json::parse(r.out);
    for (const auto& s : plan["scenes"]) action[s["name"].get<std::string>()] = s["action"].get<std::string>();
    EXPECT_EQ(action["quick"], "skip");
    EXPECT_EQ(action["level"], "bake");
}

TEST(CliBatch, ShardsPartitionTheManifestExactly) {
    TempDir dir;
    // Scenes of different sizes (costs), some equal (ties), and per-scene presets and densities.
    nlohmann::json scenes = nlohmann::json::array();
    const int count = 11;
    for (int i = 0; i < count; ++i) {
        const std::string name = "s" + std::to_string(i) + ".gltf";
        std::ofstream(dir.file(name)) << std::string(std::size_t(1000 + 700 * (i % 4) * (i % 3)), ' ') << "{}";
        nlohmann::json e = {{"scene", name}, {"output", "out/" + std::to_string(i)}, {"name", "s" + std::to_string(i)}};
        if (i % 5 == 2) e["settings"] = {{"preset", "high"}};
        if (i % 5 == 3) e["settings"] = {{"texels-per-unit", 40}};
        scenes.push_back(e);
    }
    const std::string manifest = dir.file("m.json");
    writeJson(manifest, {{"defaults", {{"preset", "draft"}}}, {"scenes", scenes}});
    for (int n = 1; n <= 5; ++n) {
        std::map<int, int> owner;  // scene index → shard that bakes it
        for (int i = 0; i < n; ++i) {
            const auto r = runHemibake({"batch", manifest, "--shard", std::to_string(i) + "/" + std::to_string(n), "--dry-run", "--json"});
            ASSERT_EQ(r.exitCode, 0) << r.err;
            const auto plan = nlohmann::json::parse(r.out);
            ASSERT_EQ(plan["scenes"].size(), std::size_t(count));
            for (const auto& s : plan["scenes"]) {
                if (s["action"] == "other-shard") continue;
                EXPECT_EQ(s["shard"], i);
                EXPECT_FALSE(owner.count(s["index"])) << "scene " << s["index"] << " in two shards (N=" << n << ")";
                owner[s["index"]] = i;
            }
        }
        EXPECT_EQ(owner.size(), std::size_t(count)) << "N=" << n << ": some scene is in no shard";
        if (n <= count) {
            std::set<int> used;
            for (const auto& [scene, shard] : owner) used.insert(shard);
            EXPECT_EQ(used.size(), std::size_t(n)) << "N=" << n << ": an empty shard";
        }
    }
}

TEST(CliBatch, BadManifestAndOptions) {
    TempDir dir;
    auto r = runHemibake({"batch", dir.file("missing.json")});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("missing.json: manifest not found"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;

    writeJson(dir.file("reserved.json"), {{"scenes", {{{"scene", "a.gltf"}, {"output", "o"}, {"settings", {{"output", "x"}}}}}}});
    r = runHemibake({"batch", dir.file("reserved.json")});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("reserved.json: scene 0 (a) \"settings\" sets 'output'"), std::string::npos) << r.err;

    writeJson(dir.file("twice.json"), {{"scenes", {{{"scene", "a.gltf"}, {"output", "o"}}, {{"scene", "b.gltf"}, {"output", "o/"}}}}});
    r = runHemibake({"batch", dir.file("twice.json")});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("is used by another scene"), std::string::npos) << r.err;

    writeJson(dir.file("ok.json"), {{"scenes", nlohmann::json::array()}});
    for (const char* shard : {"2/2", "1", "a/b", "0/0", "-1/2"})
        EXPECT_EQ(runHemibake({"batch", dir.file("ok.json"), "--shard", shard}).exitCode, 2) << shard;
    EXPECT_EQ(runHemibake({"batch", dir.file("ok.json")}).exitCode, 0);
}

TEST(CliBatch, HelpExplainsEveryKnob) {
    const auto r = runHemibake({"batch", "--help"});
    EXPECT_EQ(r.exitCode, 0);
    for (const char* knob : {"--shard", "--force", "--dry-run", "--summary", "--json", "--progress", "defaults", "settings"})
        EXPECT_NE(r.out.find(knob), std::string::npos) << knob;
}
