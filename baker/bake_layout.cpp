#include "baker/bake_layout.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "mesh/errors.h"
#include "mesh/gltf_loader.h"

namespace hemibake {

UnwrapSettings unwrapSettingsFor(const LightmapSettings& lightmap, double texelsPerUnit) {
    UnwrapSettings u;
    u.texelsPerUnit = texelsPerUnit;
    u.maxAtlasSize = lightmap.maxAtlasSize;
    u.paddingTexels = lightmap.paddingTexels;
    u.keepExistingUv = lightmap.keepExistingUv;
    return u;
}

double defaultTexelsPerUnit(const std::string& preset, double sceneDiagonalM) {
    // Small scenes get a fixed number of texels along their diagonal; large ones a floor in texels per metre
    // like common engine defaults (Unity: 40), so a 50 m level is not baked at 40 cm per texel.
    struct Density { const char* preset; double alongDiagonal; double perMetreFloor; };
    constexpr Density kDensity[] = {{"draft", 64, 8}, {"medium", 128, 16}, {"high", 256, 32}, {"ultra", 512, 64}};
    const double diagonal = sceneDiagonalM > 0.0 ? sceneDiagonalM : 1.0;
    for (const Density& d : kDensity)
        if (preset == d.preset) return std::max(d.alongDiagonal / diagonal, d.perMetreFloor);
    return std::max(128.0 / diagonal, 16.0);
}

BakeLayout loadBakeLayout(const std::filesystem::path& outDir) {
    namespace fs = std::filesystem;
    BakeLayout layout;
    layout.outDir = outDir;
    const fs::path reportPath = outDir / "bake.json";
    std::ifstream in(reportPath);
    if (!in) throw InputError(reportPath.string(), "not found (is this a hemibake bake directory?)");
    try {
        layout.report = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
        throw InputError(reportPath.string(), std::string("is not valid JSON: ") + e.what());
    }
    const nlohmann::json& r = layout.report;
    if (r.value("format", "") != "hemibake-bake/1")
        throw InputError(reportPath.string(), "format is not hemibake-bake/1");
    if (!r.contains("lightmap") || !r["lightmap"].contains("texelsPerUnit"))
        throw InputError(reportPath.string(), "has no lightmap section (the bake wrote no lightmaps)");
    std::string scenePath = r.value("sceneAbsolute", r.value("scene", ""));
    if (!fs::exists(scenePath)) scenePath = r.value("scene", "");
    layout.scene = loadGltf(scenePath);

    const nlohmann::json& lm = r["lightmap"];
    LightmapSettings settings;
    settings.maxAtlasSize = lm.value("maxAtlasSize", settings.maxAtlasSize);
    settings.paddingTexels = lm.value("paddingTexels", settings.paddingTexels);
    settings.keepExistingUv = lm.value("keepExistingUv", settings.keepExistingUv);
    layout.atlas = unwrapScene(layout.scene, unwrapSettingsFor(settings, lm["texelsPerUnit"].get<double>()));
    layout.texels = computeTexels(layout.scene, layout.atlas);
    for (const auto& f : lm.value("files", nlohmann::json::array())) layout.lightmapFiles.push_back(f.get<std::string>());
    if (layout.lightmapFiles.size() != layout.texels.size())
        throw InputError(reportPath.string(), "lists " + std::to_string(layout.lightmapFiles.size()) + " lightmaps but the "
                                              "scene unwraps into " + std::to_string(layout.texels.size()) + " atlases");
    return layout;
}

}  // namespace hemibake
