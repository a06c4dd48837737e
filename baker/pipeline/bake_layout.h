#pragma once
// What a bake's texels are, rebuilt from its bake.json: the input scene is reloaded and unwrapped with the
// recorded settings (unwrapping is deterministic), so the reference path tracer and `compare` address exactly
// the texels the bake wrote, atlas for atlas.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "baker/pipeline/bake_settings.h"
#include "mesh/scene.h"
#include "mesh/texels.h"
#include "mesh/uv_atlas.h"

namespace hemibake {

struct BakeLayout {
    std::filesystem::path outDir;
    nlohmann::json report;                  // bake.json as written
    BakeSettings settings;                  // its "settings", read back
    Scene scene;
    UvAtlas atlas;
    std::vector<AtlasTexels> texels;        // per atlas, as the bake computed them
    std::vector<std::string> lightmapFiles; // per atlas, relative to outDir (e.g. "lightmaps/0.exr")
};

// Throws InputError naming the file when bake.json is missing or malformed or the scene cannot be loaded.
BakeLayout loadBakeLayout(const std::filesystem::path& outDir);

}  // namespace hemibake
