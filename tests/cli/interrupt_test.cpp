// `hemibake bake` killed outright (SIGKILL: no handler runs, no destructor, no cleanup) in the middle of writing its
// output, then run again into the same OUT: the second bake succeeds and OUT holds the bake and nothing else (no
// temporary file of the killed run). (SIGTERM through `batch`: cli_batch_test.)
//
// The kill lands mid-write deterministically: before the bake reaches its writes, the test puts named pipes (FIFOs)
// where the bake's temporary files will go (baker/atomic_output: OUT/<path>/.tmp-<pid>-<name>), with room for 4 KiB.
// The bake opens one, writes until the pipe is full and blocks there; the test sees the first bytes arrive and
// kills it. What is left is what a bake killed while writing leaves: a temporary file, a half-written OUT.
#include <chrono>
#include <cstdio>
#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <poll.h>
#include <set>
#include <sstream>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/gltf_fixture.h"
#include "support/gltf_validator.h"
#include "support/spawn_hemibake.h"

namespace fs = std::filesystem;
using hemibake::test::runHemibake;
using hemibake::test::TempDir;

namespace {

// Every file and folder under `dir`, relative to it.
std::set<std::string> listing(const fs::path& dir) {
    std::set<std::string> names;
    for (const auto& e : fs::recursive_directory_iterator(dir)) names.insert(fs::relative(e.path(), dir).string());
    return names;
}

bool anyTemporary(const std::set<std::string>& names) {
    for (const std::string& n : names)
        if (fs::path(n).filename().string().rfind(".tmp-", 0) == 0) return true;
    return false;
}

}  // namespace

TEST(CliBakeInterrupted, SigkillMidWriteThenRebakeLeavesOnlyTheBake) {
    TempDir dir;
    const std::string scene = hemibake::test::sharedScene("cornell_box.gltf");
    const fs::path out = dir.path() / "out";
    // A few seconds: draft, small hemicubes, one thread; 64 texels/m makes the lightmap PNG and the glb far larger
    // than the 4 KiB the pipes hold.
    const std::vector<std::string> args = {"bake", scene, "-o", out.string(), "--preset", "draft", "--hemicube-res", "16",
                                           "--threads", "1", "--texels-per-unit", "64", "--no-preview"};
    // Everything up to the writes (load, solve, lightmaps) takes the bake a second or more; the pipes are in place
    // long before.
    fs::create_directories(out / "lightmaps");
    pid_t pid = hemibake::test::spawnHemibake(args, dir.file("err"));
    ASSERT_GT(pid, 0);
    const std::string tmp = ".tmp-" + std::to_string(pid) + "-";
    const fs::path pipes[] = {out / "lightmaps" / (tmp + "0.png"), out / (tmp + "cornell_box.glb")};
    std::vector<pollfd> readers;
    for (const fs::path& p : pipes) {
        ASSERT_EQ(::mkfifo(p.c_str(), 0644), 0) << p;
        const int fd = ::open(p.c_str(), O_RDONLY | O_NONBLOCK);  // a reader, so the bake's open() does not block
        ASSERT_GE(fd, 0) << p;
        ASSERT_GE(::fcntl(fd, F_SETPIPE_SZ, 4096), 4096);
        readers.push_back({fd, POLLIN, 0});
    }
    // Wait for the first bytes (up to 10 minutes: sanitizer builds are slow); the writer is then blocked on a full
    // pipe, mid-file.
    bool writing = false;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(10);
    while (!writing && std::chrono::steady_clock::now() < deadline) {
        if (::poll(readers.data(), readers.size(), 200) > 0)
            for (const pollfd& r : readers) writing |= (r.revents & POLLIN) != 0;
        if (!writing && ::waitpid(pid, nullptr, WNOHANG) == pid) {
            pid = -1;
            break;
        }
    }
    int status = 0;
    if (pid > 0) {
        ASSERT_EQ(::kill(pid, SIGKILL), 0);
        ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    }
    for (const pollfd& r : readers) ::close(r.fd);
    std::ostringstream err;
    err << std::ifstream(dir.file("err")).rdbuf();
    ASSERT_TRUE(writing) << "the bake never wrote into its temporary files (did atomic_output's naming change?):\n" << err.str();
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
    // Killed mid-write: a temporary file and a half-written OUT (no bake.json).
    const std::set<std::string> left = listing(out);
    ASSERT_TRUE(anyTemporary(left)) << "nothing to clean up: the kill did not land mid-write";
    std::string what;
    for (const std::string& n : left) what += " " + n;
    std::printf("killed mid-write; OUT held:%s\n", what.c_str());
    EXPECT_FALSE(left.count("bake.json"));

    // The same bake into the same OUT.
    const auto again = runHemibake(args);
    ASSERT_EQ(again.exitCode, 0) << again.err;
    const std::set<std::string> after = listing(out);
    EXPECT_FALSE(anyTemporary(after)) << "temporary files left behind";
    const nlohmann::json report = nlohmann::json::parse(std::ifstream(out / "bake.json"));
    std::set<std::string> expected = {"bake.json", "cornell_box.glb", "lightmaps"};
    for (const auto& f : report["lightmap"]["files"]) {
        expected.insert(f.get<std::string>());
        expected.insert(fs::path(f.get<std::string>()).replace_extension(".png").string());
    }
    EXPECT_EQ(after, expected);
    EXPECT_GLBS_VALID(out);
}

// The sweep takes only what is stale: the temporary file of a process that still runs (another bake writing into
// the same folder) stays, as does anything not named like a temporary file.
TEST(CliBakeInterrupted, TemporariesOfRunningProcessesStay) {
    TempDir dir;
    const fs::path out = dir.path() / "out";
    fs::create_directories(out / "lightmaps");
    const std::string live = ".tmp-" + std::to_string(::getpid()) + "-0.exr";  // this test process runs
    std::ofstream(out / "lightmaps" / live) << "being written";
    std::ofstream(out / "notes.tmp-1-x") << "a user's file";
    std::ofstream(out / ".tmp-x-1") << "not a pid";
    const auto r = runHemibake({"bake", hemibake::test::sharedScene("cornell_box.gltf"), "-o", out.string(), "--preset", "draft",
                                "--hemicube-res", "16", "--threads", "1", "--texels-per-unit", "16", "--no-preview"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::set<std::string> after = listing(out);
    EXPECT_TRUE(after.count("lightmaps/" + live));
    EXPECT_TRUE(after.count("notes.tmp-1-x"));
    EXPECT_TRUE(after.count(".tmp-x-1"));
    EXPECT_TRUE(after.count("bake.json"));
    EXPECT_GLBS_VALID(out);
}
