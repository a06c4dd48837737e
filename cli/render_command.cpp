// `hemibake render OUT/ --camera … -o IMG.exr`: the baked scene as an engine shows it (radiance = ρ × lightmap
// + L_e, bilinear lightmap sampling, OSMesa), framed exactly like `hemibake reference SCENE --camera …` so the
// two images compare pixel for pixel with `hemibake compare`.
#include <filesystem>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "baker/output/baked_scene_view.h"
#include "baker/output/exr_io.h"
#include "baker/output/radiance_preview.h"
#include "baker/pipeline/bake_layout.h"
#include "baker/util/rgb_image.h"
#include "cli/camera_options.h"
#include "cli/command.h"
#include "cli/progress.h"
#include "mesh/errors.h"

namespace hemibake::cli {

namespace {

namespace fs = std::filesystem;

struct RenderOptions {
    std::string outDir;
    std::string output;
    CameraOptions camera;
    std::vector<float> sky;
    int samplesPerAxis = 3;
    bool json = false;
    bool progress = false;
};

int run(const RenderOptions& o) {
    ProgressLine progress(o.progress);
    progress.update("loading the bake", true);
    const BakeLayout layout = loadBakeLayout(o.outDir);
    std::vector<LightmapImage> lightmaps;
    for (const std::string& file : layout.lightmapFiles) lightmaps.push_back(readLightmapExr(layout.outDir / file));
    for (std::size_t a = 0; a < lightmaps.size() && a < layout.atlas.atlases.size(); ++a)
        if (lightmaps[a].size != layout.atlas.atlases[a].size)
            throw InputError((layout.outDir / layout.lightmapFiles[a]).string(),
                             "is " + std::to_string(lightmaps[a].size) + " texels wide but the bake's atlas " +
                                 std::to_string(a) + " is " + std::to_string(layout.atlas.atlases[a].size));
    if (lightmaps.size() != layout.atlas.atlases.size())
        throw InputError((layout.outDir / "bake.json").string(),
                         "lists " + std::to_string(lightmaps.size()) + " lightmaps for " +
                             std::to_string(layout.atlas.atlases.size()) + " atlases");

    const std::string scenePath = layout.report.value("scene", std::string("the bake's scene"));
    const Camera camera = chooseCamera(layout.scene, scenePath, o.camera);
    const int width = o.camera.width, height = imageHeight(o.camera, camera);
    glm::vec3 sky(0.0f);
    const nlohmann::json settings = layout.report.value("settings", nlohmann::json::object());
    if (settings.contains("skyRadiance") && settings["skyRadiance"].is_array() && settings["skyRadiance"].size() == 3)
        for (int c = 0; c < 3; ++c) sky[c] = settings["skyRadiance"][std::size_t(c)].get<float>();
    if (o.sky.size() == 3) sky = glm::vec3(o.sky[0], o.sky[1], o.sky[2]);

    progress.update("rendering " + std::to_string(width) + "×" + std::to_string(height), true);
    const RgbImage image = renderBakedScene(layout.scene, layout.atlas, lightmaps, camera, width, height, sky, o.samplesPerAxis);
    const fs::path exr(o.output), png = fs::path(o.output).replace_extension(".png");
    writeRgbExr(exr, image);
    const float exposure = writeRadiancePreviewPng(png, image);
    progress.finish("rendered " + exr.string());
    if (o.json) {
        nlohmann::json j{{"format", "hemibake-render/1"},
                         {"bake", o.outDir},
                         {"camera", camera.name},
                         {"width", width},
                         {"height", height},
                         {"files", {{"radiance", exr.string()}, {"preview", png.string()}}},
                         {"previewExposure", exposure}};
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << exr.string() << "\n";
    }
    return 0;
}

}  // namespace

CommandRunner addRenderCommand(CLI::App& app) {
    auto o = std::make_shared<RenderOptions>();
    CLI::App* cmd = app.add_subcommand(
        "render",
        "Render a bake as an engine shows it (radiance = ρ × lightmap + L_e, bilinear lightmaps, OSMesa): OUT/ --camera … "
        "-o IMG.exr (plus IMG.png). Same framing as `reference SCENE --camera …`, for `compare`");
    cmd->add_option("bake", o->outDir, "A bake directory (written by `hemibake bake -o OUT/`)")->required();
    cmd->add_option("-o,--output", o->output, "The radiance image, OpenEXR (a PNG preview is written beside it)")->required();
    addCameraOptions(*cmd, o->camera);
    cmd->add_option("--sky", o->sky, "Uniform sky radiance R,G,B where nothing is hit (default: the bake's)")
        ->delimiter(',')->expected(3);
    cmd->add_option("--samples", o->samplesPerAxis, "Sub-pixel samples per axis (box filter, like the reference's pixels)")
        ->capture_default_str()->check(CLI::Range(1, 8));
    cmd->add_flag("--json", o->json, "Print the figures (size, camera, files) as JSON");
    cmd->add_flag("--progress", o->progress, "Report progress on stderr even when it is not a terminal");
    cmd->final_callback([o]() {
        validateCameraOptions(o->camera);
        if (fs::path(o->output).extension() != ".exr")
            throw CLI::ValidationError("--output", "the image is written as OpenEXR: -o must end in .exr");
    });
    return [o]() { return run(*o); };
}

}  // namespace hemibake::cli
