#pragma once
// What makes a batch scene "already baked": a stamp file in OUT, written last, holding hashes of the scene's
// input content (the glTF and every buffer and image it references) and of the settings it was baked with.
// A scene is skipped only when its output is complete and both hashes still match.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace hemibake::cli {

inline constexpr const char* kBatchStampFile = "batch-stamp.json";

// The glTF (or .glb) file plus the external files its buffers and images name by URI (data: URIs are part of the
// file already). Missing referenced files are listed anyway: hashing them records their absence, and the bake
// reports them. A file that is not parsable glTF stands alone.
std::vector<std::filesystem::path> sceneInputFiles(const std::filesystem::path& scene);

// Hex digest over the names (relative to the scene's folder), sizes and bytes of sceneInputFiles(scene).
std::string inputHash(const std::filesystem::path& scene);

// Hex digest of the settings (canonical JSON: keys sorted) and the hemibake version that bakes them.
std::string settingsHash(const nlohmann::json& settings, const std::string& version);

// Total size of the input files in bytes (0 for missing ones); the sharding cost model's size term.
std::uintmax_t inputBytes(const std::filesystem::path& scene);

struct BatchStamp {
    std::string inputHash;
    std::string settingsHash;
};

// True when OUT holds a complete bake (bake.json plus the glb and every lightmap it lists) and a stamp equal to
// `expected`.
bool bakeIsUpToDate(const std::filesystem::path& out, const std::filesystem::path& scene, const BatchStamp& expected);

// Writes OUT/batch-stamp.json atomically.
void writeBatchStamp(const std::filesystem::path& out, const std::filesystem::path& scene, const nlohmann::json& settings,
                     const BatchStamp& stamp);

}  // namespace hemibake::cli
