#pragma once
// Runs the Khronos glTF validator (scripts/validate-gltf.mjs, npm package gltf-validator installed by
// scripts/install-deps.sh) from tests. Header-only: tests/CMakeLists.txt compiles only test_support.cpp from here.
//
//   EXPECT_GLTF_VALID(path);       // 0 validator errors in one file
//   EXPECT_GLBS_VALID(directory);  // 0 errors in every .glb under a folder (a bake's OUT/), and at least one there
//   EXPECT_GLBS_VALID_BUT_FOR_INPUT(directory, input);  // no errors but the (invalid) input's own
//
// A test that cannot run the validator (no Node.js, or no validator package) FAILS, saying what is missing: a
// check that silently does not happen is worse than none (issue 17).
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>
#include <sys/wait.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace hemibake::test {

struct GltfValidation {
    std::string file;
    int exitCode = -1;
    int errors = -1, warnings = -1, infos = -1, hints = -1;
    nlohmann::json report;  // the script's --json line for this file
    std::string output;     // everything the script printed (for all files of one run)
};

// Why the validator cannot run here, or "" when it can.
inline std::string gltfValidatorUnavailable() {
    if (std::system("command -v node >/dev/null 2>&1") != 0)
        return "node (Node.js) is not installed, so the Khronos glTF validator cannot run (scripts/install-deps.sh "
               "installs Debian's nodejs and npm, then the validator)";
    const char* custom = std::getenv("HEMIBAKE_GLTF_VALIDATOR");
    const std::filesystem::path package = custom && *custom
                                              ? std::filesystem::path(custom)
                                              : std::filesystem::path(HEMIBAKE_SOURCE_DIR) / "tools" / "node_modules" / "gltf-validator";
    std::error_code ec;
    if (!std::filesystem::exists(package / "package.json", ec))
        return "the Khronos glTF validator is not installed at " + package.string() + " (run scripts/install-deps.sh)";
    return "";
}

// Validates the files in one run of the script; one result per file, in order.
inline std::vector<GltfValidation> validateGltfFiles(const std::vector<std::string>& files) {
    std::vector<GltfValidation> results(files.size());
    for (std::size_t i = 0; i < files.size(); ++i) results[i].file = files[i];
    if (files.empty()) return results;
    // For looking at what a test wrote: HEMIBAKE_TEST_KEEP_DIR=/some/folder keeps a copy of every validated file.
    if (const char* keep = std::getenv("HEMIBAKE_TEST_KEEP_DIR"); keep && *keep) {
        std::error_code ec;
        std::filesystem::create_directories(keep, ec);
        for (const std::string& file : files)
            std::filesystem::copy_file(file, std::filesystem::path(keep) / std::filesystem::path(file).filename(),
                                       std::filesystem::copy_options::overwrite_existing, ec);
    }
    // 4 MB of JavaScript stack (the default is under 1 MB): the validator walks node hierarchies recursively and
    // overflows on the 20,000-deep one the tests bake. Well inside the usual 8 MB stack limit.
    std::string command = std::string("node --stack-size=4000 '") + HEMIBAKE_SOURCE_DIR + "/scripts/validate-gltf.mjs' --json";
    for (const std::string& file : files) command += " '" + file + "'";
    command += " 2>&1";
    std::string output;
    int exitCode = -1;
    if (FILE* pipe = popen(command.c_str(), "r")) {
        std::array<char, 4096> chunk{};
        while (std::fgets(chunk.data(), int(chunk.size()), pipe)) output += chunk.data();
        const int status = pclose(pipe);
        exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    // One JSON object per file per line, each naming its file.
    std::size_t begin = 0;
    while (begin < output.size()) {
        std::size_t end = output.find('\n', begin);
        if (end == std::string::npos) end = output.size();
        const std::string line = output.substr(begin, end - begin);
        begin = end + 1;
        if (line.empty() || line[0] != '{') continue;
        const nlohmann::json report = nlohmann::json::parse(line, nullptr, false);
        if (!report.is_object() || !report.contains("file")) continue;
        for (GltfValidation& v : results)
            if (report["file"] == v.file) {
                v.report = report;
                v.errors = report.value("errors", -1);
                v.warnings = report.value("warnings", -1);
                v.infos = report.value("infos", -1);
                v.hints = report.value("hints", -1);
            }
    }
    for (GltfValidation& v : results) {
        v.exitCode = exitCode;
        v.output = output;
    }
    return results;
}

inline GltfValidation validateGltf(const std::string& file) { return validateGltfFiles({file}).front(); }

// Every .glb under `dir`, sorted.
inline std::vector<std::string> glbFilesUnder(const std::filesystem::path& dir) {
    std::vector<std::string> files;
    std::error_code ec;
    for (auto it = std::filesystem::recursive_directory_iterator(dir, ec); !ec && it != std::filesystem::recursive_directory_iterator();
         it.increment(ec))
        if (it->is_regular_file() && it->path().extension() == ".glb") files.push_back(it->path().string());
    std::sort(files.begin(), files.end());
    return files;
}

// Every error the validator reports in `files`, as "code at pointer" (severity error only).
inline std::vector<std::string> validatorErrors(const GltfValidation& v) {
    std::vector<std::string> errors;
    if (v.report.contains("messages") && v.report["messages"].is_array())
        for (const nlohmann::json& m : v.report["messages"])
            if (m.value("severity", "") == "error")
                errors.push_back(m.value("code", "?") + " at " + (m.contains("pointer") ? m["pointer"].dump() : "?"));
    return errors;
}

// 0 validator errors in each of `files` (at least one), or, with `input` given, no error but those the input file
// already has (a bake keeps the input's nodes and materials as they are). Fails, never skips, when the validator
// cannot run.
inline ::testing::AssertionResult gltfFilesValid(const std::vector<std::string>& files, const std::string& what,
                                                 const std::string& input = "") {
    if (const std::string unavailable = gltfValidatorUnavailable(); !unavailable.empty())
        return ::testing::AssertionFailure() << "cannot validate " << what << ": " << unavailable;
    if (files.empty()) return ::testing::AssertionFailure() << "no glTF file to validate in " << what;
    std::vector<std::string> inherited;
    if (!input.empty()) {
        const GltfValidation in = validateGltf(input);
        if (!in.report.is_object())
            return ::testing::AssertionFailure() << "the glTF validator gave no report for " << input << ":\n" << in.output;
        inherited = validatorErrors(in);
        if (inherited.empty())
            return ::testing::AssertionFailure() << input << " has no validator error to inherit: validate its output plainly";
    }
    ::testing::AssertionResult result = ::testing::AssertionSuccess();
    bool failed = false;
    for (const GltfValidation& v : validateGltfFiles(files)) {
        if (!v.report.is_object()) {
            failed = true;
            result = ::testing::AssertionFailure() << "the glTF validator gave no report for " << v.file << ":\n" << v.output;
            continue;
        }
        std::printf("glTF validator: %s: %d errors, %d warnings, %d infos, %d hints\n", v.file.c_str(), v.errors, v.warnings,
                    v.infos, v.hints);
        std::vector<std::string> own;
        for (const std::string& e : validatorErrors(v))
            if (std::find(inherited.begin(), inherited.end(), e) == inherited.end()) own.push_back(e);
        if (v.errors != 0 && (input.empty() || !own.empty())) {
            if (!failed) result = ::testing::AssertionFailure();
            failed = true;
            result << v.file << ": " << v.errors << " validator errors" << (input.empty() ? "" : " not in " + input) << ":\n"
                   << v.report.dump(1) << "\n";
        }
    }
    return result;
}

}  // namespace hemibake::test

#define EXPECT_GLTF_VALID(path) EXPECT_TRUE(::hemibake::test::gltfFilesValid({std::string(path)}, std::string(path)))
#define EXPECT_GLBS_VALID(dir) \
    EXPECT_TRUE(::hemibake::test::gltfFilesValid(::hemibake::test::glbFilesUnder(dir), std::filesystem::path(dir).string()))
// For bakes of deliberately invalid input: the output may carry the input's own validator errors, and no other.
#define EXPECT_GLBS_VALID_BUT_FOR_INPUT(dir, input)                                                                     \
    EXPECT_TRUE(::hemibake::test::gltfFilesValid(::hemibake::test::glbFilesUnder(dir), std::filesystem::path(dir).string(), \
                                                 std::string(input)))
