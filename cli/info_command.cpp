// `hemibake info SCENE`: what is in a scene and what baking it would cost (patch and element counts).
#include <iomanip>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli/command.h"
#include "mesh/gltf_loader.h"
#include "mesh/islands.h"
#include "mesh/subdivision.h"
#include "cli/json_vectors.h"

namespace hemibake::cli {

namespace {

struct InfoOptions {
    std::string scenePath;
    bool json = false;
    SubdivisionSettings subdivision;
};


const char* lightTypeName(LightType t) {
    switch (t) {
        case LightType::Point: return "point";
        case LightType::Spot: return "spot";
        case LightType::Directional: return "directional";
    }
    return "?";
}

nlohmann::json describe(const Scene& scene, const SubdivisionSettings& settings) {
    nlohmann::json j;
    j["format"] = "hemibake-info/1";
    j["scene"] = scene.path;
    j["nodes"] = scene.report.nodes;
    j["meshNodes"] = scene.report.meshNodes;
    j["primitives"] = scene.report.primitives;
    j["triangles"] = scene.triangleCount();
    j["degenerateTrianglesDropped"] = scene.report.degenerateTriangles;
    j["skippedPrimitives"] = scene.report.skippedPrimitives;
    j["materials"] = nlohmann::json::array();
    for (const Material& m : scene.materials)
        j["materials"].push_back({{"name", m.name},
                                  {"reflectance", jsonVec(m.reflectanceFactor)},
                                  {"textured", m.reflectanceTexture >= 0},
                                  {"emittedRadiance", jsonVec(m.emittedRadiance)},
                                  {"doubleSided", m.doubleSided}});
    j["emitters"] = nlohmann::json::array();
    for (const MeshInstance& inst : scene.instances) {
        const Material& m = scene.materials[std::size_t(inst.material)];
        if (!m.isEmissive()) continue;
        double area = 0.0;
        for (auto f : inst.mesh.faces()) area += inst.mesh.faceArea(f);
        j["emitters"].push_back({{"node", inst.source.nodeName},
                                 {"material", m.name},
                                 {"areaM2", area},
                                 {"emittedRadiance", jsonVec(m.emittedRadiance)},
                                 {"powerWatts", jsonVec(M_PI * area * glm::dvec3(m.emittedRadiance))}});
    }
    j["emittedPowerWatts"] = jsonVec(scene.emittedPowerWatts());
    j["lights"] = nlohmann::json::array();
    for (const PunctualLight& l : scene.lights)
        j["lights"].push_back({{"name", l.name},
                               {"type", lightTypeName(l.type)},
                               {"intensity", jsonVec(l.intensity)},
                               {"position", jsonVec(l.position)},
                               {"direction", jsonVec(l.direction)}});
    j["cameras"] = nlohmann::json::array();
    for (const Camera& c : scene.cameras)
        j["cameras"].push_back({{"name", c.name},
                                {"position", jsonVec(c.position)},
                                {"forward", jsonVec(c.forward)},
                                {"yfovRadians", c.yfovRadians}});
    const Bounds b = scene.bounds();
    j["bounds"] = {{"min", jsonVec(b.min)}, {"max", jsonVec(b.max)}};
    j["surfaceAreaM2"] = scene.surfaceAreaM2();
    const SceneIslands islands = SceneIslands::ofScene(scene);
    j["islands"] = {{"count", islands.size()}, {"largestDiagonalM", islands.largestDiagonalM()}};
    const SubdivisionStats s = countSubdivision(scene, settings);
    j["subdivision"] = {{"cutAlongSolids", settings.cutAlongSolids},
                        {"patchSizeM", settings.patchSizeM},
                        {"elementSizeM", settings.elementSizeM},
                        {"emitterPatchSizeM", settings.emitterPatchSizeM > 0 ? settings.emitterPatchSizeM
                                                                              : settings.patchSizeM / 4.0},
                        {"patches", s.patches},
                        {"elements", s.elements},
                        {"emitterPatches", s.emitterPatches},
                        {"emitterElements", s.emitterElements}};
    j["warnings"] = scene.report.warnings;
    return j;
}

std::string fmt3(const nlohmann::json& v, int precision = 4) {
    std::ostringstream o;
    o << std::setprecision(precision) << v[0].get<double>() << " " << v[1].get<double>() << " " << v[2].get<double>();
    return o.str();
}

void printText(const nlohmann::json& j) {
    std::cout << "scene       " << j["scene"].get<std::string>() << "\n"
              << "nodes       " << j["nodes"] << " (" << j["meshNodes"] << " with meshes)\n"
              << "primitives  " << j["primitives"] << " (" << j["skippedPrimitives"] << " points/lines skipped)\n"
              << "triangles   " << j["triangles"] << " (" << j["degenerateTrianglesDropped"] << " degenerate dropped)\n"
              << "bounds      " << fmt3(j["bounds"]["min"]) << "  ..  " << fmt3(j["bounds"]["max"]) << " m\n"
              << "area        " << j["surfaceAreaM2"].get<double>() << " m²\n"
              << "islands     " << j["islands"]["count"] << " (largest diagonal "
              << j["islands"]["largestDiagonalM"].get<double>() << " m; presets size patches and texels by it)\n"
              << "materials   " << j["materials"].size() << "\n";
    for (const auto& m : j["materials"])
        std::cout << "  " << std::left << std::setw(16) << m["name"].get<std::string>() << " ρ " << fmt3(m["reflectance"], 3)
                  << (m["textured"].get<bool>() ? " × texture" : "")
                  << (m["doubleSided"].get<bool>() ? "  double-sided" : "") << "\n";
    std::cout << "emitters    " << j["emitters"].size() << ", total power " << fmt3(j["emittedPowerWatts"], 6)
              << " W (R G B)\n";
    for (const auto& e : j["emitters"])
        std::cout << "  " << std::left << std::setw(16) << e["node"].get<std::string>() << " L_e "
                  << fmt3(e["emittedRadiance"]) << " W/m²/sr, area " << e["areaM2"].get<double>() << " m², power "
                  << fmt3(e["powerWatts"], 6) << " W\n";
    std::cout << "lights      " << j["lights"].size() << "\n";
    for (const auto& l : j["lights"])
        std::cout << "  " << std::left << std::setw(16) << l["name"].get<std::string>() << " " << l["type"].get<std::string>()
                  << " intensity " << fmt3(l["intensity"]) << "\n";
    std::cout << "cameras     " << j["cameras"].size() << "\n";
    for (const auto& c : j["cameras"]) std::cout << "  " << c["name"].get<std::string>() << " at " << fmt3(c["position"]) << "\n";
    const auto& s = j["subdivision"];
    std::cout << "patches     " << s["patches"] << " (patch size " << s["patchSizeM"].get<double>() << " m; "
              << s["emitterPatches"] << " on emitters at " << s["emitterPatchSizeM"].get<double>() << " m)\n"
              << "elements    " << s["elements"] << " (element size " << s["elementSizeM"].get<double>() << " m)\n";
    for (const auto& w : j["warnings"]) std::cout << "warning     " << w.get<std::string>() << "\n";
}

}  // namespace

CommandRunner addInfoCommand(CLI::App& app) {
    auto opts = std::make_shared<InfoOptions>();
    CLI::App* cmd = app.add_subcommand("info", "Describe a glTF scene: geometry, materials, emitters and their power, "
                                               "lights, cameras, and the patch/element counts a bake would use");
    cmd->add_option("scene", opts->scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
    cmd->add_flag("--json", opts->json, "Print the same information as one JSON object");
    cmd->add_option("--patch-size", opts->subdivision.patchSizeM,
                    "Longest edge of a shooting patch, metres")->capture_default_str()->check(CLI::PositiveNumber);
    cmd->add_option("--element-size", opts->subdivision.elementSizeM,
                    "Longest edge of a receiving element, metres")->capture_default_str()->check(CLI::PositiveNumber);
    cmd->add_option("--emitter-patch-size", opts->subdivision.emitterPatchSizeM,
                    "Longest edge of an emitter patch, metres (0 = patch size / 4)")
        ->capture_default_str()->check(CLI::NonNegativeNumber);
    cmd->add_flag("--no-solid-cuts", [opts](std::int64_t) { opts->subdivision.cutAlongSolids = false; },
                  "Count without cutting faces along the closed solids that cross them (as `bake --no-solid-cuts`)");
    return [opts]() {
        const Scene scene = loadGltf(opts->scenePath);
        const nlohmann::json j = describe(scene, opts->subdivision);
        if (opts->json)
            std::cout << j.dump(2) << "\n";
        else
            printText(j);
        return 0;
    };
}

}  // namespace hemibake::cli
