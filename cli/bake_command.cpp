// `hemibake bake SCENE -o OUT/`: load, subdivide, solve, and write the bake (CONVENTIONS.md "Bake output layout").
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include <tbb/global_control.h>

#include "baker/adaptive_refinement.h"
#include "baker/atomic_output.h"
#include "baker/bake_layout.h"
#include "baker/bake_report.h"
#include "baker/baked_scene_view.h"
#include "baker/radiance_preview.h"
#include "baker/surface_agreement.h"
#include "baker/exr_io.h"
#include "baker/gltf_writer.h"
#include "baker/inside_geometry.h"
#include "baker/lightmap_baker.h"
#include "baker/lightmap_seams.h"
#include "baker/png_preview.h"
#include "baker/embree_scene.h"
#include "baker/presets.h"
#include "baker/radiosity_solver.h"
#include "cli/bake_probes.h"
#include "cli/command.h"
#include "cli/progress.h"
#include "mesh/gltf_loader.h"
#include "mesh/subdivision.h"
#include "raster/hemicube_pool.h"

namespace hemibake::cli {

namespace {

constexpr int kPreviewWidth = 640;  // pixels; height from the camera's aspect ratio

struct BakeOptions {
    std::string scenePath;
    std::string outDir;
    std::string preset = "medium";
    std::optional<double> patchSize, elementSize, emitterPatchSize, epsilon, maxTime, proximity, formFactorCacheMiB;
    std::optional<int> hemicubeRes, gatherSweeps, adaptiveLevels;
    std::optional<double> adaptiveThreshold;
    std::optional<std::uint64_t> maxShots;
    std::optional<std::string> solver, emitters;
    std::optional<int> emitterSamples;
    std::vector<float> sky;
    float sunDiameterDeg = 0.0f;
    bool noAmbient = false;
    bool noPreview = false;
    int threads = 0;
    std::uint64_t seed = 1;
    bool progress = false;
    std::optional<double> texelsPerUnit;
    std::optional<int> maxAtlasSize, padding, lattice;
    std::optional<double> interpTolerance;
    std::optional<std::string> texelMode;
    std::string uvMode = "unwrap";
    std::string gltfMode = "lightmap";
    ProbeOptions probes;
};

class StageClock {
public:
    double lap() {
        const auto now = std::chrono::steady_clock::now();
        const double s = std::chrono::duration<double>(now - last_).count();
        last_ = now;
        return s;
    }
private:
    std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

BakeSettings resolveSettings(const BakeOptions& o, double sceneDiagonalM) {
    BakeSettings s = presetSettings(o.preset, sceneDiagonalM);
    if (o.patchSize) s.subdivision.patchSizeM = *o.patchSize;
    if (o.elementSize) s.subdivision.elementSizeM = *o.elementSize;
    if (o.patchSize && !o.elementSize) s.subdivision.elementSizeM = std::min(s.subdivision.elementSizeM, *o.patchSize);
    if (o.emitterPatchSize) s.subdivision.emitterPatchSizeM = *o.emitterPatchSize;
    if (o.epsilon) s.solver.epsilon = *o.epsilon;
    if (o.maxTime) s.solver.maxTimeSeconds = *o.maxTime;
    if (o.maxShots) s.solver.maxShots = *o.maxShots;
    if (o.hemicubeRes) s.solver.hemicubeResolution = *o.hemicubeRes;
    if (o.gatherSweeps) {
        s.solver.gatherSweeps = *o.gatherSweeps;
        s.solver.maxGatherSweeps = std::max(*o.gatherSweeps, 1);
    }
    if (o.proximity) s.solver.proximityFactor = *o.proximity;
    if (o.formFactorCacheMiB) s.solver.formFactorCacheMiB = *o.formFactorCacheMiB;
    if (o.adaptiveLevels) s.adaptive.levels = *o.adaptiveLevels;
    if (o.adaptiveThreshold) s.adaptive.threshold = *o.adaptiveThreshold;
    if (o.solver) s.solver.kind = parseSolverKind(*o.solver);
    if (o.emitters) s.lighting.emitters = parseEmitterLighting(*o.emitters);
    if (o.emitterSamples) s.lighting.emitterSamples = *o.emitterSamples;
    s.solver.ambientCorrection = !o.noAmbient;
    s.solver.threads = o.threads;
    s.solver.seed = o.seed;
    if (o.sky.size() == 3) s.lighting.skyRadiance = glm::vec3(o.sky[0], o.sky[1], o.sky[2]);
    s.lighting.sunAngularDiameterRad = float(o.sunDiameterDeg * M_PI / 180.0);
    s.lightmap.texelsPerUnit = o.texelsPerUnit ? *o.texelsPerUnit : defaultTexelsPerUnit(s.preset, sceneDiagonalM);
    if (o.maxAtlasSize) s.lightmap.maxAtlasSize = *o.maxAtlasSize;
    if (o.padding) s.lightmap.paddingTexels = *o.padding;
    if (o.lattice) s.lightmap.latticeStep = *o.lattice;
    if (o.interpTolerance) s.lightmap.interpolationTolerance = *o.interpTolerance;
    if (o.texelMode) s.lightmap.mode = *o.texelMode == "interpolate" ? TexelMode::Interpolate : TexelMode::Gather;
    s.lightmap.keepExistingUv = o.uvMode == "keep";
    return s;
}

std::string percent(double fraction) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g%%", 100.0 * fraction);
    return buf;
}

int runBake(const BakeOptions& o) {
    namespace fs = std::filesystem;
    ProgressLine progress(o.progress);
    StageClock clock;
    BakeReport report;
    report.scenePath = o.scenePath;

    const Scene scene = loadGltf(o.scenePath);
    report.timings.push_back({"load", clock.lap()});
    // Warnings go to stderr as they happen (clamped reflectance, skipped primitives, …) and into bake.json.
    std::vector<std::string> warnings;
    auto warn = [&](const std::string& w) {
        std::cerr << "hemibake: warning: " << o.scenePath << ": " << w << "\n";
        warnings.push_back(w);
    };
    for (const std::string& w : scene.report.warnings) warn(w);
    report.settings = resolveSettings(o, scene.bounds().diagonal());
    const BakeSettings& settings = report.settings;
    const ProbeJob probeJob = prepareProbeJob(o.probes, scene);  // a bad probes file fails before the solve
    if (settings.solver.hemicubeResolution < 2 || settings.solver.hemicubeResolution % 2)
        throw std::invalid_argument("--hemicube-res must be an even number >= 2");
    std::unique_ptr<tbb::global_control> threadLimit;
    if (settings.solver.threads > 0)
        threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                            std::size_t(settings.solver.threads));

    progress.update("preparing", true);
    const EmbreeScene rays(scene);
    report.timings.push_back({"setup", clock.lap()});
    const std::unique_ptr<RadiosityBake> solved = solveWithRefinement(scene, settings, rays,
                                  [&](const std::string& stage, const ConvergenceRecord& r) {
                                      std::string line = stage + ": ";
                                      if (stage == "shoot")
                                          line += std::to_string(r.shots) + " shots, unshot " + percent(r.unshotFraction) +
                                                  " of injected (stop at " + percent(settings.solver.epsilon) + ")";
                                      else
                                          line += "sweep done, error bound " + percent(r.errorBound);
                                      char t[32];
                                      std::snprintf(t, sizeof t, ", %.1f s", r.seconds);
                                      progress.update(line + t);
                                  });
    RadiosityBake& bake = *solved;
    report.solve = bake.report;
    std::size_t emitting = 0;
    for (const glm::vec3& l : bake.mesh.elements.emittedRadiance) emitting += (l.x > 0.0f || l.y > 0.0f || l.z > 0.0f);
    if (settings.lighting.emitters == EmitterLighting::Rays && emitting > 0 && !bake.report.emittersByRays)
        warn(std::to_string(emitting) + " emitting elements (more than " + std::to_string(settings.lighting.maxRayTracedEmitters) +
             "): emitters shoot through hemicubes instead of rays (their shadows follow the element grid)");
    report.triangles = scene.triangleCount();
    report.patches = bake.mesh.patches.size();
    report.elements = bake.mesh.elements.size();
    report.extra["exposedArea"] = {{"elementsTrimmed", bake.exposedArea.elementsTrimmed},
                                   {"elementsCovered", bake.exposedArea.elementsCovered},
                                   {"areaRemovedM2", bake.exposedArea.areaRemovedM2}};
    report.extra["refinement"] = {{"levels", settings.adaptive.levels},
                                  {"threshold", settings.adaptive.threshold},
                                  {"elementsBefore", bake.elementsBeforeRefinement},
                                  {"elementsAfter", bake.mesh.elements.size()},
                                  {"regions", bake.refinementRegions}};
    report.timings.push_back({"solve", clock.lap()});
    report.timings.push_back({"direct", report.solve.directSeconds});
    report.timings.push_back({"shoot", report.solve.shootSeconds});
    report.timings.push_back({"gather", report.solve.gatherSeconds});
    progress.finish("solved: " + report.solve.stopReason + ", " + std::to_string(report.solve.shots) + " shots, " +
                    std::to_string(report.solve.gatherSweeps) + " gather sweeps, unshot " +
                    percent(report.solve.unshotFraction) + ", error bound " + percent(report.solve.errorBound));
    // Probes and the irradiance volume see the solved elements (displayRadiosity / π) and the sky.
    runProbeJob(probeJob, o.probes, scene, bake.mesh, bake.solution, settings.lighting.skyRadiance, fs::path(o.outDir),
                progress, report);
    clock.lap();  // the probe stages timed themselves

    // Lightmaps: unwrap, place texels, bake E/π per texel, write EXR + preview + lightmapped glb.
    const fs::path out(o.outDir);
    progress.update("unwrapping", true);
    const UvAtlas atlas = unwrapScene(scene, unwrapSettingsFor(settings.lightmap, settings.lightmap.texelsPerUnit));
    const std::vector<AtlasTexels> texels = computeTexels(scene, atlas);
    for (const std::string& w : atlas.warnings) warn(w);
    report.timings.push_back({"unwrap", clock.lap()});
    LightmapStats lightmapStats;
    std::vector<LightmapImage> images = bakeLightmaps(
        scene, bake.mesh, bake.solution, atlas, texels, *bake.pool, rays, settings, lightmapStats,
        [&](std::size_t done, std::size_t total) {
            progress.update("lightmaps: " + std::to_string(done) + " / " + std::to_string(total) + " texels");
        });
    // Dilation first: bilinear taps at a seam reach into the padding, so stitching must see (and adjust) the
    // final padding values, or dilating afterwards would reopen the seams it closed.
    for (LightmapImage& image : images) lightmapStats.dilated += dilate(image, settings.lightmap.dilationTexels);
    const SeamStats seams = stitchSeams(scene, atlas, images, settings.lightmap.stitchSeams);
    report.timings.push_back({"lightmaps", clock.lap()});
    nlohmann::json surfaces = nlohmann::json::array();
    double worstSurface = 0.0;
    std::vector<std::vector<std::uint8_t>> insideGeometry;
    for (const AtlasTexels& t : texels)
        insideGeometry.push_back(texelsInsideGeometry(scene, rays, t, settings.lightmap.invalidBackfaceFraction));
    for (const SurfaceAgreement& s : compareSurfaceMeans(scene, bake.mesh, bake.solution, texels, images, insideGeometry)) {
        worstSurface = std::max(worstSurface, s.relativeDifference());
        surfaces.push_back({{"node", s.nodeName},
                            {"instance", s.instance},
                            {"texels", s.texels},
                            {"elementMeanIrradianceOverPi", {s.elementMean.x, s.elementMean.y, s.elementMean.z}},
                            {"lightmapMeanIrradianceOverPi", {s.lightmapMean.x, s.lightmapMean.y, s.lightmapMean.z}},
                            {"relativeDifference", s.relativeDifference()}});
    }
    GltfWriteOptions gltfOptions;
    gltfOptions.mode = *parseGltfMode(o.gltfMode);
    nlohmann::json files = nlohmann::json::array(), atlases = nlohmann::json::array();
    for (std::size_t a = 0; a < images.size(); ++a) {
        const std::string rel = lightmapRelativePath(gltfOptions, int(a));
        writeLightmapExr(out / rel, images[a]);
        writeLightmapPreviewPng((out / rel).replace_extension(".png"), images[a]);
        files.push_back(rel);
        atlases.push_back({{"size", images[a].size}, {"utilization", atlas.atlases[a].utilization}});
    }
    const std::string stem = fs::path(o.scenePath).stem().string();
    report.primitives = writeLightmappedGlb(o.scenePath, scene, atlas, images, out / (stem + ".glb"), gltfOptions);
    report.timings.push_back({"write", clock.lap()});
    if (!scene.cameras.empty() && !o.noPreview) {
        // A picture of the result from the scene's own camera: what the user would look at first.
        progress.update("preview render", true);
        const Camera& camera = scene.cameras.front();
        const RgbImage preview = renderBakedScene(scene, atlas, images, camera, kPreviewWidth,
                                                  imageHeightFor(camera, kPreviewWidth), settings.lighting.skyRadiance);
        writeRgbExr(out / "preview.exr", preview);
        writeRadiancePreviewPng(out / "preview.png", preview);
        report.extra["preview"] = {{"camera", camera.name}, {"exr", "preview.exr"}, {"png", "preview.png"},
                                   {"width", preview.width}, {"height", preview.height}};
        report.timings.push_back({"preview", clock.lap()});
    }
    report.extra["warnings"] = warnings;
    report.extra["sceneAbsolute"] = fs::absolute(o.scenePath).lexically_normal().string();
    report.extra["lightmap"] = {{"texelsPerUnit", settings.lightmap.texelsPerUnit},
                                {"maxAtlasSize", settings.lightmap.maxAtlasSize},
                                {"paddingTexels", settings.lightmap.paddingTexels},
                                {"keepExistingUv", settings.lightmap.keepExistingUv},
                                {"texelMode", settings.lightmap.mode == TexelMode::Gather ? "gather" : "interpolate"},
                                {"latticeStep", settings.lightmap.latticeStep},
                                {"interpolationTolerance", settings.lightmap.interpolationTolerance},
                                {"gltfMode", o.gltfMode},
                                {"files", files},
                                {"atlases", atlases},
                                {"texels", lightmapStats.texels},
                                {"renderedTexels", lightmapStats.rendered},
                                {"renderedFraction", lightmapStats.renderedFraction()},
                                {"interpolatedTexels", lightmapStats.interpolated},
                                {"invalidTexels", lightmapStats.invalid},
                                {"dilationTexels", settings.lightmap.dilationTexels},
                                {"dilatedTexels", lightmapStats.dilated},
                                {"charts", atlas.stats.charts},
                                {"surfaceAgreement", {{"maxRelativeDifference", worstSurface}, {"surfaces", surfaces}}},
                                {"seams", {{"edges", seams.seamEdges},
                                           {"samples", seams.samples},
                                           {"stitched", settings.lightmap.stitchSeams},
                                           {"maxRelativeBefore", seams.maxRelativeBefore},
                                           {"maxRelativeAfter", seams.maxRelativeAfter},
                                           {"meanRelativeBefore", seams.meanRelativeBefore},
                                           {"meanRelativeAfter", seams.meanRelativeAfter}}}};
    progress.finish("lightmaps: " + std::to_string(images.size()) + " atlas(es), " + std::to_string(lightmapStats.texels) +
                    " texels, " + percent(lightmapStats.renderedFraction()) + " rendered by hemicube, max seam step " +
                    percent(seams.maxRelativeBefore) + " -> " + percent(seams.maxRelativeAfter));

    report.peakMemoryMiB = peakResidentMemoryMiB();
    writeTextAtomically(out / "bake.json", report.toJson().dump(2) + "\n");
    std::cout << (out / "bake.json").string() << "\n";
    return 0;
}

}  // namespace

CommandRunner addBakeCommand(CLI::App& app) {
    auto o = std::make_shared<BakeOptions>();
    CLI::App* cmd = app.add_subcommand("bake", "Solve the radiosity of a glTF scene and write the bake to OUT/: <scene>.glb with "
                                               "lightmaps, lightmaps/*.exr (E/π per texel), bake.json (settings, timings, "
                                               "convergence history, power ledger, primitives)");
    cmd->add_option("scene", o->scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
    cmd->add_option("-o,--output", o->outDir, "Output directory (created if missing; files appear atomically)")->required();
    std::string presetHelp = "Speed/accuracy preset; sizes scale with the scene's bounding-box diagonal:";
    for (const PresetDescription& p : presetDescriptions()) presetHelp += "\n  " + p.name + ": " + p.summary;
    cmd->add_option("--preset", o->preset, presetHelp)->capture_default_str()->check(CLI::IsMember({"draft", "medium", "high", "ultra"}));
    cmd->add_option("--patch-size", o->patchSize, "Longest edge of a shooting patch, metres (overrides the preset)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--element-size", o->elementSize, "Longest edge of a receiving element, metres")->check(CLI::PositiveNumber);
    cmd->add_option("--emitter-patch-size", o->emitterPatchSize, "Longest edge of an emitter patch, metres (default patch size / 4)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--hemicube-res", o->hemicubeRes,
                    "Hemicube resolution R (front face R×R pixels); form-factor error falls as ~R^-1.5 (docs/accuracy.md)")
        ->check(CLI::Range(2, 4096));
    cmd->add_option("--solver", o->solver,
                    "shoot: progressive refinement only; gather: Jacobi sweeps only; hybrid: shoot, then gather at receivers")
        ->check(CLI::IsMember({"shoot", "gather", "hybrid"}));
    cmd->add_option("--epsilon", o->epsilon, "Stop shooting when unshot power <= epsilon × injected power (gather: when the "
                                             "error bound <= epsilon)")->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--max-time", o->maxTime, "Stop shooting after this many seconds (0 = no limit)")->check(CLI::NonNegativeNumber);
    cmd->add_option("--max-shots", o->maxShots, "Stop shooting after this many shots (0 = no limit)");
    cmd->add_option("--gather-sweeps", o->gatherSweeps, "Gathering sweeps after shooting (hybrid) or at most (gather)")
        ->check(CLI::Range(0, 10000));
    cmd->add_option("--proximity", o->proximity,
                    "A patch shoots from several sample points when a surface is nearer than this × its size")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--emitters", o->emitters,
                    "How emissive surfaces light the scene directly. rays: Lambert's exact formula times a shadow-ray "
                    "visibility estimate at every element and texel (sharp, alias-free; the bounces still shoot "
                    "through hemicubes); hemicube: emitters shoot their power like every other patch. Scenes with "
                    "more than 4096 emitting elements fall back to hemicube")
        ->check(CLI::IsMember({"rays", "hemicube"}));
    cmd->add_option("--emitter-samples", o->emitterSamples,
                    "Shadow rays per point towards emissive surfaces (--emitters rays); only penumbrae are noisy")
        ->check(CLI::Range(1, 4096));
    cmd->add_option("--ff-cache-mib", o->formFactorCacheMiB,
                    "Memory for form-factor rows of patches that shoot again (default 1024; 0 = render every shot). "
                    "Rows cost about 8 bytes per element a patch sees; past the budget patches render each time")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--adaptive-levels", o->adaptiveLevels,
                    "Refine elements at light/shadow boundaries this many times (each halves their size), then solve again")
        ->check(CLI::Range(0, 6));
    cmd->add_option("--adaptive-threshold", o->adaptiveThreshold,
                    "Relative radiosity difference between neighbouring elements that triggers refinement")
        ->check(CLI::Range(0.0, 10.0));
    cmd->add_flag("--no-ambient", o->noAmbient, "Do not add the ambient term for still-unshot light (Cohen et al. 1988)");
    cmd->add_option("--sky", o->sky, "Uniform sky radiance R,G,B in W·m⁻²·sr⁻¹ seen where rays escape")->delimiter(',')->expected(3);
    cmd->add_option("--sun-diameter", o->sunDiameterDeg, "Angular diameter of directional lights in degrees (0.53 = the sun; "
                                                         "0 = hard shadows)")->check(CLI::Range(0.0, 30.0));
    cmd->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(CLI::NonNegativeNumber);
    cmd->add_option("--seed", o->seed, "Seed for hemicube rotations and sampling (bakes are reproducible per seed)");
    cmd->add_option("--texels-per-unit", o->texelsPerUnit,
                    "Lightmap texels per metre (default: preset × scene size, at least 8/16/32/64 for draft..ultra)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--max-atlas-size", o->maxAtlasSize, "Largest lightmap atlas, texels (more atlases when full)")
        ->check(CLI::Range(16, 8192));
    cmd->add_option("--padding", o->padding, "Free texels between charts (>= 2 keeps bilinear filtering clean)")
        ->check(CLI::Range(0, 64));
    cmd->add_option("--texel-mode", o->texelMode,
                    "gather: a final hemicube per texel, placed adaptively; interpolate: from the element solution (fast)")
        ->check(CLI::IsMember({"gather", "interpolate"}));
    cmd->add_option("--lattice", o->lattice, "Adaptive placement: hemicubes on every Nth texel first, then midpoints only "
                                             "where the light is not locally linear (1 = every texel)")->check(CLI::IsMember({1, 2, 4, 8, 16}));
    cmd->add_option("--interp-tolerance", o->interpTolerance,
                    "Adaptive placement: a texel is interpolated when the curvature its lattice neighbours show is "
                    "below this fraction of their value")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--uv", o->uvMode, "unwrap: compute lightmap UVs; keep: use TEXCOORD_1 from the scene where present")
        ->capture_default_str()->check(CLI::IsMember({"unwrap", "keep"}));
    cmd->add_flag("--no-preview", o->noPreview,
                  "Skip the preview render from the scene's camera (preview.exr/.png): batch runs and benchmarks");
    cmd->add_option("--gltf", o->gltfMode, "lightmap: PBR materials + MOZ_lightmap; emissive: viewable anywhere (baked "
                                           "into emissive)")->capture_default_str()->check(CLI::IsMember({"lightmap", "emissive"}));
    addProbeOptions(*cmd, o->probes);
    cmd->add_flag("--progress", o->progress, "Report progress on stderr even when it is not a terminal");
    return [o]() { return runBake(*o); };
}

}  // namespace hemibake::cli
