#pragma once
// A batch manifest (`hemibake batch MANIFEST.json`): the scenes to bake, where their bakes go, and the bake options
// for each (shared defaults overridden per scene). Paths in the manifest are relative to the manifest's folder.
//
//   { "defaults": { "preset": "draft" },
//     "scenes": [ { "scene": "level.gltf", "output": "out/level", "settings": { "texels-per-unit": 20 } } ] }
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace hemibake::cli {

struct BatchScene {
    std::size_t index = 0;            // position in the manifest (ties in sharding are broken by it)
    std::string name;                 // "name" or the scene file's stem; unique within the manifest
    std::filesystem::path scene;      // resolved against the manifest's folder
    std::filesystem::path output;     // ditto
    nlohmann::json settings;          // defaults merged with the scene's own settings (an object)
};

struct BatchManifest {
    std::filesystem::path path;
    std::vector<BatchScene> scenes;
};

// Reads and checks a manifest; any problem is an InputError naming the manifest and the offending entry.
BatchManifest loadBatchManifest(const std::filesystem::path& path);

// The `hemibake bake` arguments for a settings object: {"texels-per-unit": 20, "sky": [1,1,1], "no-ambient": true}
// → --texels-per-unit 20 --sky 1,1,1 --no-ambient. Throws std::invalid_argument for values that are not
// numbers, strings, booleans or arrays of numbers.
std::vector<std::string> bakeArguments(const nlohmann::json& settings);

}  // namespace hemibake::cli
