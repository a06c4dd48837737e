// `hemibake reference`: the path-traced ground truth, either a camera image (radiance) or E/π at exactly the
// texels of an existing bake (same atlases and layout, so `compare` can diff the two texel for texel).
// Progressive (baker/progressive_reference.h): passes double the spp until --spp or --time-limit.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include "baker/output/exr_io.h"
#include "baker/output/png_preview.h"
#include "baker/output/radiance_preview.h"
#include "baker/pipeline/bake_layout.h"
#include "baker/rays/embree_scene.h"
#include "baker/reference/progressive_reference.h"
#include "baker/util/atomic_output.h"
#include "baker/util/rgb_image.h"
#include "cli/camera_options.h"
#include "cli/command.h"
#include "cli/progress.h"
#include "mesh/errors.h"
#include "mesh/gltf_loader.h"
#include "cli/json_vectors.h"

namespace hemibake::cli {

namespace {

namespace fs = std::filesystem;

struct ReferenceOptions {
    std::string scenePath;
    std::string texelsDir;
    std::string output;
    CameraOptions camera;
    std::uint32_t spp = 64;
    double timeLimitSeconds = 0.0;
    std::vector<float> sky;
    std::optional<float> sunDiameterDeg;
    std::uint64_t seed = 1;
    int maxDepth = 64;
    int threads = 0;
    bool json = false;
    bool progress = false;
};


// Command-line consistency that CLI11's needs/excludes cannot express; a violation is exit 2.
void validate(const ReferenceOptions& o) {
    if (!o.texelsDir.empty()) {
        if (!o.scenePath.empty())
            throw CLI::ValidationError("SCENE", "texel mode takes the scene from OUT/bake.json; give SCENE or --texels, not both");
        return;
    }
    if (o.scenePath.empty()) throw CLI::ValidationError("SCENE", "give a SCENE with a camera, or --texels OUT/");
    validateCameraOptions(o.camera);
    if (fs::path(o.output).extension() != ".exr")
        throw CLI::ValidationError("--output", "the camera image is written as OpenEXR: -o must end in .exr");
}

std::string summary(const ProgressiveStatus& s, std::uint32_t target, const char* what = "reference") {
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s: %u spp (target %u) in %u passes, %.2f s, %.3g Mrays/s%s", what, s.spp, target,
                  s.passes, s.seconds, s.seconds > 0.0 ? double(s.rays) / s.seconds * 1e-6 : 0.0,
                  s.timeLimited ? ", stopped by the time limit" : "");
    return buf;
}

// The spp reached is always reported on stderr (it is the figure a time limit makes uncertain).
void finish(ProgressLine& progress, const std::string& line) {
    if (progress.enabled())
        progress.finish(line);
    else
        std::cerr << line << "\n";
}

nlohmann::json statusJson(const ProgressiveStatus& s, const ReferenceOptions& o, const PathTracerSettings& tracer) {
    return {{"spp", s.spp},
            {"targetSpp", o.spp},
            {"passes", s.passes},
            {"seconds", s.seconds},
            {"rays", s.rays},
            {"raysPerSecond", s.seconds > 0.0 ? double(s.rays) / s.seconds : 0.0},
            {"timeLimited", s.timeLimited},
            {"seed", tracer.seed},
            {"settings",
             {{"timeLimitSeconds", o.timeLimitSeconds},
              {"skyRadiance", jsonVec(glm::dvec3(tracer.skyRadiance))},
              {"sunAngularDiameterRad", tracer.sunAngularDiameterRad},
              {"maxDepth", tracer.maxDepth},
              {"rouletteDepth", tracer.rouletteDepth},
              {"threads", o.threads}}}};
}

PathTracerSettings tracerSettings(const ReferenceOptions& o, const nlohmann::json& bakeSettings) {
    PathTracerSettings t;
    t.seed = o.seed;
    t.maxDepth = o.maxDepth;
    if (bakeSettings.contains("skyRadiance")) {
        const auto& s = bakeSettings["skyRadiance"];
        t.skyRadiance = glm::vec3(s[0].get<float>(), s[1].get<float>(), s[2].get<float>());
    }
    t.sunAngularDiameterRad = bakeSettings.value("sunAngularDiameterRad", 0.0f);
    if (o.sky.size() == 3) t.skyRadiance = glm::vec3(o.sky[0], o.sky[1], o.sky[2]);
    if (o.sunDiameterDeg) t.sunAngularDiameterRad = float(*o.sunDiameterDeg * M_PI / 180.0);
    return t;
}

int runCamera(const ReferenceOptions& o, ProgressLine& progress) {
    const Scene scene = loadGltf(o.scenePath);
    const Camera camera = chooseCamera(scene, o.scenePath, o.camera);
    const int width = o.camera.width;
    const int height = imageHeight(o.camera, camera);
    const PathTracerSettings tracer = tracerSettings(o, nlohmann::json::object());
    progress.update("preparing", true);
    const EmbreeScene rays(scene);
    const ProgressiveEstimate estimate = renderCameraProgressively(
        scene, rays, tracer, camera, width, height, {o.spp, o.timeLimitSeconds},
        [&](const ProgressiveStatus& s) { progress.update(summary(s, o.spp, "pass"), true); });

    RgbImage radiance(width, height), standardError(width, height);
    glm::dvec3 sum(0.0), sumVariance(0.0);
    for (std::size_t p = 0; p < radiance.pixels.size(); ++p) {
        radiance.pixels[p] = glm::vec3(estimate.mean[p]);
        standardError.pixels[p] = glm::vec3(estimate.standardError[p]);
        sum += estimate.mean[p];
        sumVariance += estimate.standardError[p] * estimate.standardError[p];
    }
    const fs::path image(o.output);
    const fs::path errorImage = standardErrorPath(image);
    const fs::path preview = fs::path(image).replace_extension(".png");
    writeRgbExr(image, radiance);
    writeRgbExr(errorImage, standardError);
    const float exposure = writeRadiancePreviewPng(preview, radiance);
    finish(progress, summary(estimate.status, o.spp));

    if (o.json) {
        const double n = double(radiance.pixels.size());
        nlohmann::json j = statusJson(estimate.status, o, tracer);
        j["format"] = "hemibake-reference/1";
        j["mode"] = "camera";
        j["scene"] = o.scenePath;
        j["camera"] = {{"name", camera.name},
                       {"position", jsonVec(camera.position)},
                       {"forward", jsonVec(glm::dvec3(camera.forward))},
                       {"up", jsonVec(glm::dvec3(camera.up))},
                       {"yfovRadians", camera.yfovRadians}};
        j["width"] = width;
        j["height"] = height;
        j["files"] = {{"radiance", image.string()}, {"standardError", errorImage.string()}, {"preview", preview.string()}};
        // The image mean and its standard error (pixels are independent estimates).
        j["imageMean"] = jsonVec(sum / n);
        j["imageMeanStandardError"] = jsonVec(glm::sqrt(sumVariance) / n);
        j["previewExposure"] = exposure;
        std::cout << j.dump(2) << "\n";
    } else {
        std::cout << image.string() << "\n";
    }
    return 0;
}

int runTexels(const ReferenceOptions& o, ProgressLine& progress) {
    const fs::path outDir(o.texelsDir), refDir(o.output);
    std::error_code ec;
    if (fs::exists(refDir, ec) && fs::equivalent(outDir, refDir, ec))
        throw InputError(refDir.string(), "is the bake directory itself; write the reference elsewhere");
    progress.update("loading the bake layout", true);
    const BakeLayout layout = loadBakeLayout(outDir);
    const nlohmann::json bakeSettings = layout.report.value("settings", nlohmann::json::object());
    const PathTracerSettings tracer = tracerSettings(o, bakeSettings);

    std::vector<SurfacePoint> points;
    for (const AtlasTexels& t : layout.texels)
        for (std::size_t i = 0; i < t.count(); ++i) points.push_back({t.position[i], t.normal[i]});
    progress.update("preparing", true);
    const EmbreeScene rays(layout.scene);
    const ProgressiveEstimate estimate = irradianceOverPiProgressively(
        layout.scene, rays, tracer, points, {o.spp, o.timeLimitSeconds},
        [&](const ProgressiveStatus& s) { progress.update(summary(s, o.spp, "pass"), true); });

    std::size_t next = 0;
    glm::dvec3 sum(0.0), sumError(0.0);
    for (std::size_t a = 0; a < layout.texels.size(); ++a) {
        const AtlasTexels& t = layout.texels[a];
        LightmapImage values, errors;
        values.resize(t.size);
        errors.resize(t.size);
        for (std::size_t i = 0; i < t.count(); ++i, ++next) {
            const std::size_t p = values.index(t.x[i], t.y[i]);
            values.irradianceOverPi[p] = glm::vec3(estimate.mean[next]);
            errors.irradianceOverPi[p] = glm::vec3(estimate.standardError[next]);
            values.state[p] = errors.state[p] = TexelState::Covered;
            sum += estimate.mean[next];
            sumError += estimate.standardError[next];
        }
        const fs::path file = refDir / layout.lightmapFiles[a];
        writeLightmapExr(file, values);
        writeLightmapExr(standardErrorPath(file), errors);
    }
    finish(progress, summary(estimate.status, o.spp));

    nlohmann::json j = statusJson(estimate.status, o, tracer);
    j["format"] = "hemibake-reference/1";
    j["mode"] = "texels";
    j["source"] = fs::absolute(outDir).lexically_normal().string();
    j["scene"] = layout.report.value("scene", "");
    if (layout.report.contains("sceneAbsolute")) j["sceneAbsolute"] = layout.report["sceneAbsolute"];
    j["lightmap"] = {{"files", layout.lightmapFiles},
                     {"texelsPerUnit", layout.report["lightmap"].value("texelsPerUnit", 0.0)},
                     {"standardErrorSuffix", kStandardErrorExtension}};
    j["texels"] = points.size();
    const double n = double(std::max<std::size_t>(points.size(), 1));
    j["meanIrradianceOverPi"] = jsonVec(sum / n);
    j["meanStandardError"] = jsonVec(sumError / n);  // per texel, averaged
    j["primitives"] = layout.report.value("primitives", nlohmann::json::array());
    writeTextAtomically(refDir / "reference.json", j.dump(2) + "\n");
    if (o.json)
        std::cout << j.dump(2) << "\n";
    else
        std::cout << (refDir / "reference.json").string() << "\n";
    return 0;
}

}  // namespace

CommandRunner addReferenceCommand(CLI::App& app) {
    auto o = std::make_shared<ReferenceOptions>();
    CLI::App* cmd = app.add_subcommand(
        "reference",
        "Path-trace the ground truth: a camera image of radiance (SCENE --camera … -o IMG.exr, plus IMG.stderr.exr and "
        "IMG.png), or E/π at exactly the texels of a bake (--texels OUT/ -o REF/, same layout as OUT/ for `compare`)");
    cmd->add_option("scene", o->scenePath, "glTF 2.0 scene (.gltf or .glb); camera mode only");
    auto* texels = cmd->add_option("--texels", o->texelsDir, "Texel mode: the bake directory whose texels to estimate");
    cmd->add_option("-o,--output", o->output, "Camera mode: the EXR image; texel mode: the output directory")->required();
    const std::vector<CLI::Option*> cameraOptions = addCameraOptions(*cmd, o->camera);
    cmd->add_option("--spp", o->spp, "Target samples per pixel or texel")->capture_default_str()->check(CLI::Range(1u, 1u << 24));
    cmd->add_option("--time-limit", o->timeLimitSeconds, "Stop after this many seconds, with the spp reached (0 = no limit)")
        ->capture_default_str()->check(CLI::NonNegativeNumber);
    cmd->add_option("--sky", o->sky, "Uniform sky radiance R,G,B in W·m⁻²·sr⁻¹ (texel mode: default the bake's)")
        ->delimiter(',')->expected(3);
    cmd->add_option("--sun-diameter", o->sunDiameterDeg, "Angular diameter of directional lights in degrees (texel mode: "
                                                         "default the bake's)")->check(CLI::Range(0.0, 30.0));
    cmd->add_option("--seed", o->seed, "Seed of the random streams (results are reproducible per seed without --time-limit)")
        ->capture_default_str();
    cmd->add_option("--max-depth", o->maxDepth, "Path segments after the first surface (1 = direct light only)")
        ->capture_default_str()->check(CLI::Range(1, 100000));
    cmd->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(CLI::NonNegativeNumber);
    cmd->add_flag("--json", o->json, "Print the run's figures (spp reached, time, rays, files) as JSON");
    cmd->add_flag("--progress", o->progress, "Report progress on stderr even when it is not a terminal");
    for (CLI::Option* camera : cameraOptions) texels->excludes(camera);
    cmd->final_callback([o]() { validate(*o); });
    return [o]() {
        ProgressLine progress(o->progress);
        std::unique_ptr<tbb::global_control> threadLimit;
        if (o->threads > 0)
            threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                                std::size_t(o->threads));
        return o->texelsDir.empty() ? runCamera(*o, progress) : runTexels(*o, progress);
    };
}

}  // namespace hemibake::cli
