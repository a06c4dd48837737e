// `hemibake batch MANIFEST.json`: bakes many scenes, each in its own `hemibake bake` child process, skipping those
// whose outputs are already up to date, optionally only this machine's shard; writes one summary, batch.json.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <stdio.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "baker/util/atomic_output.h"
#include "cli/batch_manifest.h"
#include "cli/batch_shards.h"
#include "cli/batch_stamp.h"
#include "cli/child_process.h"
#include "cli/command.h"
#include "cli/interrupt_guard.h"
#include "cli/progress.h"

namespace hemibake::cli {

namespace {

namespace fs = std::filesystem;

struct BatchOptions {
    std::string manifestPath;
    std::string summaryPath;
    std::string shard = "0/1";
    bool force = false;
    bool dryRun = false;
    bool json = false;
    bool progress = false;
};

struct PlannedScene {
    const BatchScene* scene = nullptr;
    double cost = 0.0;
    int shard = 0;
    BatchStamp stamp;
    bool upToDate = false;
};

std::string formatSeconds(double s) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f s", s);
    return buf;
}

// The child's error line without the "hemibake: " every CLI message starts with.
std::string withoutProgramName(std::string line) {
    const std::string prefix = "hemibake: ";
    if (line.rfind(prefix, 0) == 0) line.erase(0, prefix.size());
    return line;
}

// Moves a finished staging folder into place as OUT in one step: renameat2(RENAME_EXCHANGE) swaps it with an
// existing OUT atomically, so OUT is at every moment either the whole old bake or the whole new one.
void replaceDirectory(const fs::path& staging, const fs::path& out) {
    std::error_code ec;
    if (fs::exists(fs::symlink_status(out, ec))) {
        if (::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, out.c_str(), RENAME_EXCHANGE) != 0)
            throw std::runtime_error(out.string() + ": cannot replace with the new bake: " + std::strerror(errno));
        fs::remove_all(staging, ec);  // now the previous bake
    } else {
        fs::rename(staging, out);
    }
}

// Staging folders sit beside OUT (same filesystem, so the final rename is atomic) and are hidden.
std::string stagingPrefix(const fs::path& out) { return "." + out.filename().string() + ".batch-"; }

void removeStaleStaging(const fs::path& out) {
    std::error_code ec;
    const fs::path parent = out.parent_path().empty() ? fs::path(".") : out.parent_path();
    if (!fs::is_directory(parent, ec)) return;
    const std::string prefix = stagingPrefix(out);
    for (const auto& entry : fs::directory_iterator(parent, ec))
        if (entry.path().filename().string().rfind(prefix, 0) == 0) fs::remove_all(entry.path(), ec);
}

nlohmann::json planJson(const std::vector<PlannedScene>& plan, const ShardSpec& shard, bool force) {
    nlohmann::json scenes = nlohmann::json::array();
    for (const PlannedScene& p : plan) {
        const char* action = p.shard != shard.index ? "other-shard" : (p.upToDate && !force ? "skip" : "bake");
        scenes.push_back({{"name", p.scene->name},
                          {"index", p.scene->index},
                          {"scene", p.scene->scene.string()},
                          {"output", p.scene->output.string()},
                          {"shard", p.shard},
                          {"cost", p.cost},
                          {"action", action}});
    }
    return {{"format", "hemibake-batch-plan/1"}, {"shard", {{"index", shard.index}, {"count", shard.count}}}, {"scenes", scenes}};
}

struct SceneResult {
    std::string status;  // ok, failed, skipped
    std::string reason;  // for skipped: up to date / interrupted
    std::string error;
    double seconds = 0.0;
    std::optional<double> peakMemoryMiB;
    std::optional<int> exitCode;
};

SceneResult bakeScene(const PlannedScene& p, const nlohmann::json& settings, ProgressLine& progress, const std::string& tag) {
    const BatchScene& s = *p.scene;
    SceneResult r;
    const auto start = std::chrono::steady_clock::now();
    removeStaleStaging(s.output);
    if (s.output.has_parent_path()) fs::create_directories(s.output.parent_path());
    const fs::path staging = (s.output.has_parent_path() ? s.output.parent_path() : fs::path(".")) /
                             (stagingPrefix(s.output) + std::to_string(::getpid()));
    fs::create_directories(staging);  // exists from the start, so a partial bake can only ever be in here
    std::vector<std::string> args = {"hemibake", "bake", s.scene.string(), "-o", staging.string(), "--progress"};
    for (std::string& a : bakeArguments(settings)) args.push_back(std::move(a));

    ChildOutcome outcome;
    {
        ChildProcess child("/proc/self/exe", args);
        outcome = child.wait([&](const std::string& line) { progress.update(tag + line); }, &InterruptGuard::pending);
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.peakMemoryMiB = outcome.peakMemoryMiB;
    if (outcome.exited) r.exitCode = outcome.exitCode;
    std::error_code ec;
    const bool complete = outcome.exited && outcome.exitCode == 0 && fs::is_regular_file(staging / "bake.json", ec);
    if (complete && !InterruptGuard::pending()) {
        try {
            writeBatchStamp(staging, s.scene, settings, p.stamp);  // last, so a stamp implies a complete bake
            replaceDirectory(staging, s.output);
            r.status = "ok";
            return r;
        } catch (const std::exception& e) {
            r.error = e.what();
        }
    } else if (InterruptGuard::pending()) {
        r.error = "interrupted";
    } else if (!outcome.exited) {
        r.error = "crashed (signal " + std::to_string(outcome.signal) + ", " + strsignal(outcome.signal) + ")" +
                  (outcome.lastLine.empty() ? "" : "; last output: " + outcome.lastLine);
    } else {
        r.error = outcome.lastLine.empty() ? "bake exited with code " + std::to_string(outcome.exitCode)
                                           : withoutProgramName(outcome.lastLine);
    }
    fs::remove_all(staging, ec);
    r.status = "failed";
    return r;
}

int runBatch(const BatchOptions& o) {
    InterruptGuard interrupts;
    const auto start = std::chrono::steady_clock::now();
    const ShardSpec shard = parseShardSpec(o.shard);
    const BatchManifest manifest = loadBatchManifest(o.manifestPath);
    const std::string version = HEMIBAKE_VERSION;

    std::vector<double> costs;
    std::vector<PlannedScene> plan;
    for (const BatchScene& s : manifest.scenes) {
        PlannedScene p;
        p.scene = &s;
        p.cost = estimatedBakeCost(double(inputBytes(s.scene)), s.settings);
        costs.push_back(p.cost);
        plan.push_back(p);
    }
    const std::vector<int> shards = assignShards(costs, shard.count);
    for (std::size_t i = 0; i < plan.size(); ++i) {
        PlannedScene& p = plan[i];
        p.shard = shards[i];
        if (p.shard != shard.index) continue;
        p.stamp = {inputHash(p.scene->scene), settingsHash(p.scene->settings, version)};
        p.upToDate = bakeIsUpToDate(p.scene->output, p.scene->scene, p.stamp);
    }

    if (o.dryRun) {
        const nlohmann::json j = planJson(plan, shard, o.force);
        if (o.json) {
            std::cout << j.dump(2) << "\n";
        } else {
            for (const auto& s : j["scenes"])
                std::cout << s["action"].get<std::string>() << "\t" << s["name"].get<std::string>() << "\tshard "
                          << s["shard"].get<int>() << "\t" << s["output"].get<std::string>() << "\n";
        }
        return 0;
    }

    ProgressLine progress(o.progress);
    std::size_t mine = 0, done = 0, failed = 0;
    for (const PlannedScene& p : plan) mine += p.shard == shard.index;
    nlohmann::json scenes = nlohmann::json::array();
    std::string firstFailure;
    for (const PlannedScene& p : plan) {
        if (p.shard != shard.index) continue;
        const BatchScene& s = *p.scene;
        const std::string tag = "[" + std::to_string(++done) + "/" + std::to_string(mine) + "] " + s.name + ": ";
        SceneResult r;
        if (InterruptGuard::pending()) {
            r.status = "skipped";
            r.reason = "interrupted";
        } else if (p.upToDate && !o.force) {
            r.status = "skipped";
            r.reason = "up to date";
            progress.finish(tag + "skipped (up to date)");
        } else {
            progress.update(tag + "baking " + s.scene.string(), true);
            r = bakeScene(p, s.settings, progress, tag);
            if (r.status == "ok")
                progress.finish(tag + "ok in " + formatSeconds(r.seconds) + ", peak " + std::to_string(int(*r.peakMemoryMiB + 0.5)) + " MiB");
            else
                progress.finish(tag + "FAILED: " + r.error);
        }
        if (r.status == "failed") {
            ++failed;
            if (firstFailure.empty()) firstFailure = s.name + ": " + r.error;
        }
        nlohmann::json e = {{"name", s.name},
                            {"index", s.index},
                            {"scene", s.scene.string()},
                            {"output", s.output.string()},
                            {"status", r.status},
                            {"seconds", r.seconds},
                            {"peakMemoryMiB", r.peakMemoryMiB ? nlohmann::json(*r.peakMemoryMiB) : nlohmann::json(nullptr)},
                            {"error", r.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.error)},
                            {"settings", s.settings},
                            {"inputHash", p.stamp.inputHash},
                            {"settingsHash", p.stamp.settingsHash},
                            {"cost", p.cost}};
        if (!r.reason.empty()) e["reason"] = r.reason;
        if (r.exitCode) e["exitCode"] = *r.exitCode;
        scenes.push_back(std::move(e));
    }

    std::map<std::string, int> counts = {{"ok", 0}, {"failed", 0}, {"skipped", 0}};
    for (const auto& e : scenes) ++counts[e["status"].get<std::string>()];
    const int signal = InterruptGuard::pending();
    nlohmann::json summary = {{"format", "hemibake-batch/1"},
                              {"manifest", fs::absolute(manifest.path).lexically_normal().string()},
                              {"shard", {{"index", shard.index}, {"count", shard.count}}},
                              {"force", o.force},
                              {"interrupted", signal ? nlohmann::json(strsignal(signal)) : nlohmann::json(nullptr)},
                              {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()},
                              {"counts", counts},
                              {"scenes", scenes}};
    fs::path summaryPath = o.summaryPath;
    if (summaryPath.empty()) {
        const std::string name = shard.count == 1 ? "batch.json"
                                                  : "batch.shard-" + std::to_string(shard.index) + "-of-" + std::to_string(shard.count) + ".json";
        summaryPath = (manifest.path.has_parent_path() ? manifest.path.parent_path() : fs::path(".")) / name;
    }
    writeTextAtomically(summaryPath, summary.dump(2) + "\n");
    if (o.json)
        std::cout << summary.dump(2) << "\n";
    else
        std::cout << summaryPath.string() << "\n";

    if (signal) {
        std::cerr << "hemibake: batch interrupted (" << strsignal(signal) << "): " << counts["ok"] << " of " << mine
                  << " scenes baked; summary in " << summaryPath.string() << "\n";
        return 1;
    }
    if (failed) {
        std::cerr << "hemibake: " << failed << " of " << mine << " scenes failed (" << firstFailure << "); summary in "
                  << summaryPath.string() << "\n";
        return 1;
    }
    return 0;
}

}  // namespace

CommandRunner addBatchCommand(CLI::App& app) {
    auto o = std::make_shared<BatchOptions>();
    CLI::App* cmd = app.add_subcommand(
        "batch",
        "Bake every scene of a manifest, each in its own `hemibake bake` process; skip scenes already baked from the "
        "same inputs and settings; write a summary (batch.json). Manifest: {\"defaults\": {bake options}, \"scenes\": "
        "[{\"scene\": PATH, \"output\": DIR, \"name\": optional, \"settings\": {bake options}}]}, bake options "
        "named as `hemibake bake` knobs without dashes (e.g. {\"preset\": \"draft\", \"texels-per-unit\": 20}); "
        "paths relative to the manifest's folder. OUT is replaced as a whole when a scene finishes");
    cmd->add_option("manifest", o->manifestPath, "Batch manifest (JSON)")->required();
    cmd->add_option("--summary", o->summaryPath,
                    "Where to write the summary (default: batch.json beside the manifest; with --shard I/N, "
                    "batch.shard-I-of-N.json)");
    cmd->add_option("--shard", o->shard,
                    "Bake only shard I of N (0 <= I < N): scenes are dealt out by estimated cost (input size × texel "
                    "density × preset), largest first, to the least-loaded shard; the same on every machine")
        ->capture_default_str()
        ->check([](const std::string& v) {
            try {
                parseShardSpec(v);
                return std::string();
            } catch (const std::invalid_argument& e) {
                return std::string(e.what());
            }
        });
    cmd->add_flag("--force", o->force, "Bake every scene of the shard even when its output is up to date");
    cmd->add_flag("--dry-run", o->dryRun,
                  "Print the plan (per scene: bake, skip = up to date, other-shard) and bake nothing");
    cmd->add_flag("--json", o->json, "Print the summary (or with --dry-run the plan) as JSON on stdout instead of its path");
    cmd->add_flag("--progress", o->progress, "Report progress across scenes and stages on stderr even when it is not a terminal");
    return [o]() { return runBatch(*o); };
}

}  // namespace hemibake::cli
