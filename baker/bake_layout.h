#pragma once
// What a bake's texels are, rebuilt from its bake.json: the input scene is reloaded and unwrapped with the
// recorded settings (unwrapping is deterministic), so the reference path tracer and `compare` address exactly
// the texels the bake wrote, atlas for atlas.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "baker/bake_settings.h"
#include "mesh/scene.h"
#include "mesh/texels.h"
#include "mesh/uv_atlas.h"

namespace hemibake {

// The unwrap settings a bake uses, from its settings and the scene size (texelsPerUnit 0 = preset default).
UnwrapSettings unwrapSettingsFor(const LightmapSettings& lightmap, double texelsPerUnit);
// Preset default density: about 64 texels along the scene diagonal per preset step, clamped to the atlas.
double defaultTexelsPerUnit(const std::string& preset, double sceneDiagonalM);

struct BakeLayout {
    std::filesystem::path outDir;
    nlohmann::json report;                  // bake.json as written
    Scene scene;
    UvAtlas atlas;
    std::vector<AtlasTexels> texels;        // per atlas, as the bake computed them
    std::vector<std::string> lightmapFiles; // per atlas, relative to outDir (e.g. "lightmaps/0.exr")
};

// Throws InputError naming the file when bake.json is missing or malformed or the scene cannot be loaded.
BakeLayout loadBakeLayout(const std::filesystem::path& outDir);

}  // namespace hemibake
