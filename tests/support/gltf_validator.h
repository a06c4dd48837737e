#pragma once
// Runs the Khronos glTF validator (scripts/validate-gltf.mjs, npm package gltf-validator installed by
// scripts/install-deps.sh) from tests. Header-only: tests/CMakeLists.txt compiles only test_support.cpp from here.
//
//   EXPECT_GLTF_VALID(path);  // 0 validator errors; skips the test (GTEST_SKIP) only when node is not installed
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <sys/wait.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace hemibake::test {

struct GltfValidation {
    bool nodeAvailable = false;
    int exitCode = -1;
    int errors = -1, warnings = -1, infos = -1, hints = -1;
    nlohmann::json report;  // the script's --json line
    std::string output;     // everything the script printed
};

inline bool nodeAvailable() { return std::system("command -v node >/dev/null 2>&1") == 0; }

inline GltfValidation validateGltf(const std::string& file) {
    GltfValidation v;
    v.nodeAvailable = nodeAvailable();
    if (!v.nodeAvailable) return v;
    // For looking at what a test wrote: HEMIBAKE_TEST_KEEP_DIR=/some/folder keeps a copy of every validated file.
    if (const char* keep = std::getenv("HEMIBAKE_TEST_KEEP_DIR"); keep && *keep) {
        std::error_code ec;
        std::filesystem::create_directories(keep, ec);
        std::filesystem::copy_file(file, std::filesystem::path(keep) / std::filesystem::path(file).filename(),
                                   std::filesystem::copy_options::overwrite_existing, ec);
    }
    const std::string command = std::string("node '") + HEMIBAKE_SOURCE_DIR + "/scripts/validate-gltf.mjs' --json '" + file +
                                "' 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return v;
    std::array<char, 4096> chunk{};
    while (std::fgets(chunk.data(), int(chunk.size()), pipe)) v.output += chunk.data();
    const int status = pclose(pipe);
    v.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    // The last line that is a JSON object is the report.
    std::size_t end = v.output.size();
    while (end > 0) {
        std::size_t begin = v.output.rfind('\n', end - 1);
        begin = begin == std::string::npos ? 0 : begin + 1;
        const std::string line = v.output.substr(begin, end - begin);
        if (!line.empty() && line[0] == '{') {
            v.report = nlohmann::json::parse(line, nullptr, false);
            if (v.report.is_object()) {
                v.errors = v.report.value("errors", -1);
                v.warnings = v.report.value("warnings", -1);
                v.infos = v.report.value("infos", -1);
                v.hints = v.report.value("hints", -1);
            }
            break;
        }
        if (begin == 0) break;
        end = begin - 1;
    }
    return v;
}

}  // namespace hemibake::test

#define EXPECT_GLTF_VALID(path)                                                                                     \
    do {                                                                                                            \
        const ::hemibake::test::GltfValidation validation_ = ::hemibake::test::validateGltf(path);                  \
        if (!validation_.nodeAvailable)                                                                             \
            GTEST_SKIP() << "node (Node.js) is not installed: cannot run the Khronos glTF validator on " << (path); \
        ASSERT_EQ(validation_.exitCode, 0) << "glTF validator failed on " << (path) << ":\n" << validation_.output;  \
        EXPECT_EQ(validation_.errors, 0) << validation_.output;                                                     \
        std::printf("glTF validator: %s: %d errors, %d warnings, %d infos, %d hints\n", std::string(path).c_str(),  \
                    validation_.errors, validation_.warnings, validation_.infos, validation_.hints);                \
    } while (0)
