#include "baker/pipeline/bake_layout.h"

#include <fstream>

#include "mesh/errors.h"
#include "mesh/gltf_loader.h"

namespace hemibake {

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
    if (!r.contains("lightmap") || !r.contains("settings"))
        throw InputError(reportPath.string(), "has no lightmap section (the bake wrote no lightmaps)");
    try {
        layout.settings = bakeSettingsFromJson(r["settings"]);
    } catch (const std::invalid_argument& e) {
        throw InputError(reportPath.string(), e.what());
    }
    std::string scenePath = r.value("sceneAbsolute", r.value("scene", ""));
    if (!fs::exists(scenePath)) scenePath = r.value("scene", "");
    layout.scene = loadGltf(scenePath);

    const nlohmann::json& lm = r["lightmap"];
    // Bakes from before every knob was in "settings" kept the density in the lightmap section only.
    if (!(layout.settings.lightmap.texelsPerUnit > 0.0) && lm.contains("texelsPerUnit") && lm["texelsPerUnit"].is_number())
        layout.settings.lightmap.texelsPerUnit = lm["texelsPerUnit"].get<double>();
    if (!(layout.settings.lightmap.texelsPerUnit > 0.0))
        throw InputError(reportPath.string(), "settings.texelsPerUnit is not a positive density");
    layout.atlas = unwrapScene(layout.scene, unwrapSettingsFor(layout.settings.lightmap));
    layout.texels = computeTexels(layout.scene, layout.atlas, layout.settings.lightmap.texels);
    for (const auto& f : lm.value("files", nlohmann::json::array())) layout.lightmapFiles.push_back(f.get<std::string>());
    if (layout.lightmapFiles.size() != layout.texels.size())
        throw InputError(reportPath.string(), "lists " + std::to_string(layout.lightmapFiles.size()) + " lightmaps but the "
                                              "scene unwraps into " + std::to_string(layout.texels.size()) + " atlases");
    return layout;
}

}  // namespace hemibake
