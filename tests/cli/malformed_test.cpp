// Malformed glTFs (tests/data/malformed, each with the problem its error must name in expected.json): `hemibake
// bake` exits 1 with exactly one stderr line naming the file and the problem, and leaves no output directory.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/gltf_fixture.h"

namespace fs = std::filesystem;
using hemibake::test::runHemibake;
using hemibake::test::TempDir;

namespace {

const fs::path kMalformedDir = fs::path(HEMIBAKE_SOURCE_DIR) / "tests" / "data" / "malformed";

nlohmann::json expectedErrors() {
    std::ifstream in(kMalformedDir / "expected.json");
    return nlohmann::json::parse(in);
}

}  // namespace

TEST(CliMalformed, EveryFileHasAnExpectation) {
    const nlohmann::json expected = expectedErrors();
    for (const auto& entry : fs::directory_iterator(kMalformedDir)) {
        const std::string name = entry.path().filename().string();
        if (name == "expected.json") continue;
        EXPECT_TRUE(expected.contains(name)) << name << " has no entry in expected.json";
    }
}

TEST(CliMalformed, BakeFailsWithOneLineNamingFileAndProblem) {
    const nlohmann::json expected = expectedErrors();
    int checked = 0;
    for (const auto& [name, problem] : expected.items()) {
        if (name.front() == '_') continue;  // comments
        SCOPED_TRACE(name);
        TempDir dir;
        const fs::path out = dir.path() / "out";
        const auto r = runHemibake({"bake", (kMalformedDir / name).string(), "-o", out.string(), "--preset", "draft"});
        EXPECT_EQ(r.exitCode, 1) << r.err;
        ASSERT_FALSE(r.err.empty());
        EXPECT_EQ(r.err.back(), '\n') << r.err;
        EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line:\n" << r.err;
        EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
        EXPECT_NE(r.err.find(problem.get<std::string>()), std::string::npos) << r.err;
        EXPECT_TRUE(r.out.empty()) << r.out;
        EXPECT_FALSE(fs::exists(out)) << "output directory left behind";
        ++checked;
    }
    int entries = 0;
    for (const auto& [name, problem] : expected.items()) entries += name.front() == '_' ? 0 : 1;
    EXPECT_EQ(checked, entries);  // every file listed was baked and checked
    EXPECT_GE(checked, 25);
}
