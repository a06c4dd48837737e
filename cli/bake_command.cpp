// `hemibake bake SCENE -o OUT/`: options to BakeSettings, progress to stderr; the bake itself is bakeScene
// (baker/pipeline/bake_scene.h).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <optional>

#include "baker/pipeline/bake_scene.h"
#include "baker/pipeline/presets.h"
#include "baker/util/stopwatch.h"
#include "cli/command.h"
#include "cli/probe_options.h"
#include "cli/progress.h"
#include "mesh/gltf_loader.h"

namespace hemibake::cli {

namespace {

// What the command line says; options left unset keep the preset's value for the scene's size.
struct BakeOptions {
    std::string scenePath;
    std::string outDir;
    std::string preset = "medium";
    std::optional<double> patchSize, elementSize, emitterPatchSize, epsilon, maxTime, proximity, formFactorCacheMiB;
    std::optional<int> hemicubeRes, gatherSweeps, adaptiveLevels, directStepLevels, rowRays;
    std::optional<std::string> rowSampling;
    std::optional<double> adaptiveThreshold, roomFraction, unevenShotSpread, unevenRaysPerLight;
    std::optional<std::uint64_t> maxShots;
    std::optional<std::string> solver, emitters;
    std::optional<int> emitterSamples, maxRayTracedEmitters;
    std::vector<float> sky;
    float sunDiameterDeg = 0.0f;
    bool noAmbient = false;
    bool separateSides = false;
    bool noSolidCuts = false;
    std::optional<double> gapCutFraction;
    bool noPreview = false;
    int threads = 0;
    std::uint64_t seed = 1;
    bool progress = false;
    std::optional<double> texelsPerUnit;
    std::optional<int> maxAtlasSize, padding, lattice, gatherRes, gatherRays;
    std::optional<std::string> finalGather;
    std::optional<double> interpTolerance;
    bool flatGatherDirect = false;
    std::optional<int> gapPasses;
    std::optional<std::string> texelMode;
    std::string uvMode = "unwrap";
    std::string gltfMode = "lightmap";
    ProbeSettings probes;
    ProbeOptions probeOptions;
};

template <class T, class U>
void override(const std::optional<T>& option, U& value) { if (option) value = U(*option); }
BakeSettings resolveSettings(const BakeOptions& o, double sceneDiagonalM) {
    BakeSettings s = presetSettings(o.preset, sceneDiagonalM);
    SubdivisionSettings& sub = s.solve.subdivision;
    SolverSettings& solver = s.solve.solver;
    LightingSettings& lighting = s.solve.lighting;
    override(o.patchSize, sub.patchSizeM);
    override(o.elementSize, sub.elementSizeM);
    override(o.roomFraction, s.solve.roomScale.roomFraction);
    override(o.directStepLevels, s.solve.directSteps.levels);
    if (o.patchSize && !o.elementSize) sub.elementSizeM = std::min(sub.elementSizeM, *o.patchSize);
    override(o.emitterPatchSize, sub.emitterPatchSizeM);
    override(o.epsilon, solver.epsilon);
    override(o.maxTime, solver.maxTimeSeconds);
    override(o.maxShots, solver.maxShots);
    override(o.hemicubeRes, solver.hemicubeResolution);
    override(o.rowRays, solver.rowRays);
    if (o.rowSampling) solver.rowSampling = parseRowSampling(*o.rowSampling);
    if (o.gatherSweeps) {
        solver.gatherSweeps = *o.gatherSweeps;
        solver.maxGatherSweeps = std::max(*o.gatherSweeps, 1);
    }
    override(o.proximity, solver.proximityFactor);
    override(o.unevenShotSpread, solver.unevenShotSpread);
    override(o.unevenRaysPerLight, solver.unevenRaysPerLightShare);
    override(o.formFactorCacheMiB, solver.formFactorCacheMiB);
    override(o.adaptiveLevels, s.solve.adaptive.levels);
    override(o.adaptiveThreshold, s.solve.adaptive.threshold);
    if (o.solver) solver.kind = parseSolverKind(*o.solver);
    if (o.emitters) lighting.emitters = parseEmitterLighting(*o.emitters);
    override(o.emitterSamples, lighting.emitterSamples);
    override(o.maxRayTracedEmitters, lighting.maxRayTracedEmitters);
    solver.ambientCorrection = !o.noAmbient;
    s.solve.sides.enabled = o.separateSides;
    if (o.noSolidCuts) s.solve.subdivision.cutAlongSolids = false;
    override(o.gapCutFraction, s.solve.subdivision.gapCutFraction);
    solver.threads = o.threads;
    solver.seed = o.seed;
    if (o.sky.size() == 3) lighting.skyRadiance = glm::vec3(o.sky[0], o.sky[1], o.sky[2]);
    lighting.sunAngularDiameterRad = float(o.sunDiameterDeg * M_PI / 180.0);
    override(o.texelsPerUnit, s.lightmap.texelsPerUnit);  // unset: bakeScene picks the preset's density
    override(o.maxAtlasSize, s.lightmap.maxAtlasSize);
    override(o.padding, s.lightmap.paddingTexels);
    override(o.lattice, s.lightmap.latticeStep);
    override(o.gatherRes, s.lightmap.gatherResolution);
    override(o.gatherRays, s.lightmap.gatherRays);
    if (o.finalGather) s.lightmap.finalGather = parseFinalGather(*o.finalGather);
    override(o.interpTolerance, s.lightmap.interpolationTolerance);
    if (o.flatGatherDirect) s.lightmap.gatherTexelDirect = false;
    override(o.gapPasses, s.lightmap.gapPasses);
    if (o.texelMode) s.lightmap.mode = parseTexelMode(*o.texelMode);
    s.lightmap.keepExistingUv = o.uvMode == "keep";
    s.probes = o.probes;
    applyProbeOptions(o.probeOptions, s.probes);
    s.output.gltf.mode = parseGltfMode(o.gltfMode);
    s.output.preview = !o.noPreview;
    return s;
}

int runBake(const BakeOptions& o) {
    ProgressLine progress(o.progress);
    Stopwatch loading;
    const Scene scene = loadGltf(o.scenePath);
    BakeOutput output{o.scenePath, o.outDir, loading.seconds()};
    const BakeResult result = bakeScene(scene, resolveSettings(o, presetSizingDiagonalM(scene)), output,
                                        [&](const BakeProgressEvent& e) {
                                            switch (e.kind) {
                                                case BakeProgressEvent::Kind::Update: progress.update(e.message); break;
                                                case BakeProgressEvent::Kind::Step: progress.update(e.message, true); break;
                                                case BakeProgressEvent::Kind::StageDone: progress.finish(e.message); break;
                                                case BakeProgressEvent::Kind::Warning:
                                                    std::cerr << "hemibake: warning: " << o.scenePath << ": " << e.message << "\n";
                                                    break;
                                            }
                                            return true;
                                        });
    std::cout << (output.dir / "bake.json").string() << "\n";
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
    std::string presetHelp = "Speed/accuracy preset; sizes scale with the scene's bounding-box diagonal up to 28 m, stay fixed in metres "
                             "from there to 280 m (a level's patches are room-sized whatever its extent) and follow a tenth of "
                             "the diagonal beyond (open worlds). The diagonal is the largest island's: parts within their own "
                             "size of each other, so levels placed kilometres apart are sized as one level:";
    for (const PresetDescription& p : presetDescriptions()) presetHelp += "\n  " + p.name + ": " + p.summary;
    cmd->add_option("--preset", o->preset, presetHelp)->capture_default_str()->check(CLI::IsMember({"draft", "medium", "high", "ultra"}));
    cmd->add_option("--patch-size", o->patchSize, "Longest edge of a shooting patch, metres (overrides the preset)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--element-size", o->elementSize, "Longest edge of a receiving element, metres")->check(CLI::PositiveNumber);
    cmd->add_option("--room-fraction", o->roomFraction,
                    "Elements no larger than this × their mean free path (about the size of the room they are in): "
                    "presets 1 (draft, medium), 1/2 (high), 1/3 (ultra: 0.8-0.9 m elements in 5 m rooms, whatever the "
                    "level's size); 0 = sizes from the scene diagonal only")
        ->check(CLI::Range(0.0, 10.0));
    cmd->add_option("--direct-step-levels", o->directStepLevels,
                    "Experimental: before solving, halve elements where direct light (rays) steps within them, this many times "
                    "(3 takes 1.6 m elements to 0.2 m at a hot spot's or shadow's edge). Presets 0: right on one room with a "
                    "hanging panel, but on level_small 3 levels made 190k elements, took 37 min and came out worse (under study)")
        ->check(CLI::Range(0, 6));
    cmd->add_option("--emitter-patch-size", o->emitterPatchSize, "Longest edge of an emitter patch, metres (default: the patch size when rays carry the emitters' light, else patch size / 4, so hemicube emitters shoot from close enough)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--hemicube-res", o->hemicubeRes,
                    "Hemicube resolution R (front face R×R pixels); form-factor error falls as ~R^-1.5 (docs/accuracy.md)")
        ->check(CLI::Range(2, 4096));
    cmd->add_option("--shoot-rows", o->rowSampling,
                    "How a shooting patch finds what it sees. rays (default): R squared stratified cosine rays through "
                    "Embree into the elements, from stratified points over the whole patch where its light lies, so "
                    "the near field where surfaces meet is integrated, not point-sampled; "
                    "hemicube: an item-buffer hemicube through OSMesa from the patch's centre or (something near, or "
                    "its light uneven) from up to 16 of its elements, exact delta form factors. Solve at medium: clean "
                    "10k-triangle level 23 s by rays against 84 s, the 100k level converged in 565 s where hemicubes "
                    "were stopped at 1,200 s")
        ->check(CLI::IsMember({"hemicube", "rays"}));
    cmd->add_option("--row-rays", o->rowRays,
                    "Rays per shooting row by rays, in all, split over the points the shot leaves from (0 = R squared, "
                    "as a texel's final gather; 3 R squared, the hemicube's pixel count, doubled the 100k level's solve "
                    "for the same error per object)")
        ->check(CLI::Range(0, 1 << 20));
    cmd->add_option("--uneven-rays-per-light", o->unevenRaysPerLight,
                    "Rows by rays: an uneven shot (never cached) whose light is a share s of all its patch has given "
                    "off traces min(1, this × s) of the row's rays, at least 1/16 (default 4; 0 = always all). At "
                    "medium the overlapping 10k level's shooting took 34 s with all rays, 17 s at 4, same error per object")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--solver", o->solver,
                    "shoot: progressive refinement only; gather: Jacobi sweeps only; hybrid: shoot, then gather at receivers")
        ->check(CLI::IsMember({"shoot", "gather", "hybrid"}));
    cmd->add_option("--epsilon", o->epsilon, "Stop shooting when, at every element, the light still to arrive is <= epsilon "
                                             "× what it has (gather: when the error bound <= epsilon)")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--max-time", o->maxTime, "Stop shooting after this many seconds (0 = no limit)")->check(CLI::NonNegativeNumber);
    cmd->add_option("--max-shots", o->maxShots, "Stop shooting after this many shots (0 = no limit)");
    cmd->add_option("--gather-sweeps", o->gatherSweeps, "Gathering sweeps after shooting (hybrid) or at most (gather)")
        ->check(CLI::Range(0, 10000));
    cmd->add_option("--proximity", o->proximity,
                    "A patch shoots from several sample points when a surface is nearer than this × its size")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--uneven-shot-spread", o->unevenShotSpread,
                    "A patch whose unshot light lies unevenly over it (more than this fraction away from an even spread) "
                    "shoots it from the elements it lies on, picked in proportion to it (a hot spot above a hanging "
                    "panel goes back into the panel's gap, not into the room); default 0.1, 1 = never")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--emitters", o->emitters,
                    "How emissive surfaces light the scene directly. rays: Lambert's exact formula times a shadow-ray "
                    "visibility estimate at every element and texel (sharp, alias-free); hemicube: emitters shoot "
                    "their power like every other patch (their shadows follow the element grid). Scenes with more "
                    "emitter input triangles near one receiver than --max-ray-traced-emitters fall back to hemicube, "
                    "with a warning")
        ->check(CLI::IsMember({"rays", "hemicube"}));
    cmd->add_option("--max-ray-traced-emitters", o->maxRayTracedEmitters,
                    "Emitter input triangles (per side of a double-sided face) near one receiver up to which "
                    "--emitters rays holds (default 4096; counted in blocks of cells 4 element sizes wide, reported "
                    "as emitterTrianglesNearOneReceiver in bake.json). Far lamps are clustered and cost little, so "
                    "a level's size does not count; each emitter triangle near a receiver costs a contour per point, "
                    "so a densely tessellated emitting surface beside receivers is what the limit guards")
        ->check(CLI::Range(0, 1 << 24));
    cmd->add_option("--emitter-samples", o->emitterSamples,
                    "Shadow rays per point towards emissive surfaces (--emitters rays); only penumbrae are noisy")
        ->check(CLI::Range(1, 4096));
    cmd->add_option("--ff-cache-mib", o->formFactorCacheMiB,
                    "Memory for form-factor rows of patches that shoot again (default 1024; 0 = render every shot). "
                    "Rows cost about 3 bytes per element a patch sees; past the budget patches render each time")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--adaptive-levels", o->adaptiveLevels,
                    "Refine elements at light/shadow boundaries this many times (each halves their size), then solve again")
        ->check(CLI::Range(0, 6));
    cmd->add_option("--adaptive-threshold", o->adaptiveThreshold,
                    "Relative radiosity difference between neighbouring elements that triggers refinement")
        ->check(CLI::Range(0.0, 10.0));
    cmd->add_flag("--no-ambient", o->noAmbient, "Do not add the ambient term for still-unshot light (its next bounce, where "
                                                "it will arrive, and the bounces after it)");
    cmd->add_flag("--no-solid-cuts", o->noSolidCuts,
                  "Do not cut faces where closed solids cross them (a wall standing in a floor slab): by default the buried "
                  "parts are dropped and no patch or element runs under a wall into the next room (issue 15)");
    cmd->add_option("--gap-cut-fraction", o->gapCutFraction,
                    "Also cut faces along the outline of a solid hanging in front of them closer than this × the element "
                    "size (a light panel 5 cm under a ceiling: its trapped light gets elements of its own); default 0.125, "
                    "0 = off")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_flag("--separate-sides", o->separateSides,
                  "Experimental: bisect elements that straddle a wall standing on their face (a slab under two rooms) "
                  "and split patches by side, so no light crosses the wall's footprint (issue 15: costly on levels)");
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
                    "gather: a final gather per texel (--final-gather), placed adaptively; interpolate: from the element "
                    "solution (fast)")
        ->check(CLI::IsMember({"gather", "interpolate"}));
    cmd->add_option("--lattice", o->lattice, "Adaptive placement: final gathers on every Nth texel first, then midpoints only "
                                             "where the light is not locally linear (1 = every texel)")->check(CLI::IsMember({1, 2, 4, 8, 16}));
    cmd->add_option("--final-gather", o->finalGather,
                    "How a gathered texel sees the solved scene. rays (every preset): stratified cosine rays through "
                    "Embree; hemicube: a radiance hemicube through OSMesa. Same elements, texel light and sky: on the clean "
                    "10k level at medium R squared rays gave the same per-object error in 31% of the time, per texel "
                    "2.3% RMS against 1.9% (--gather-rays 8192: 2.0% in 46%)")
        ->check(CLI::IsMember({"rays", "hemicube"}));
    cmd->add_option("--gather-rays", o->gatherRays,
                    "Rays per gathered texel with --final-gather rays, rounded down to a square (0 = R squared for the "
                    "gather resolution R: 4096 at medium). Noise falls as 1/sqrt(rays), cost rises linearly")
        ->check(CLI::Range(0, kMaxGatherRays));
    cmd->add_option("--gather-res", o->gatherRes,
                    "Final-gather resolution R (0 = the solve's --hemicube-res; every preset: 0): the hemicube's with "
                    "--final-gather hemicube, R squared rays with rays. Gathers see only bounced light and sky (direct "
                    "light is traced per texel): on a 10k level hemicubes at R=32 under medium's 64 took 30% off the "
                    "final gather and kept every room's mean, but per texel error rose 1.9% -> 2.8% RMS")
        ->check(CLI::Range(0, 4096));
    cmd->add_option("--interp-tolerance", o->interpTolerance,
                    "Adaptive placement: a texel is interpolated when the curvature its lattice neighbours show is "
                    "below this fraction of their value")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_flag("--flat-gather-direct", o->flatGatherDirect,
                  "Final gathers see each element's ray-traced direct light as its average instead of per lightmap "
                  "texel (faster by a texture lookup per pixel; darker next to hot spots smaller than an element)");
    cmd->add_option("--gap-passes", o->gapPasses,
                    "Texels facing a surface nearer than an eighth of an element (a light panel hung under a ceiling) "
                    "are gathered again, each pass seeing the texels of the one before (one bounce in the gap at texel "
                    "resolution per pass), until a pass changes them by < 0.5 %, at most this many times. Experimental "
                    "(default 0 = off; 16 to try): right in a test room at 8 texels/m, wrong on level_small at 4")
        ->check(CLI::Range(0, 16));
    cmd->add_option("--uv", o->uvMode, "unwrap: compute lightmap UVs; keep: use TEXCOORD_1 from the scene where present")
        ->capture_default_str()->check(CLI::IsMember({"unwrap", "keep"}));
    cmd->add_flag("--no-preview", o->noPreview,
                  "Skip the preview render from the scene's camera (preview.exr/.png): batch runs and benchmarks");
    cmd->add_option("--gltf", o->gltfMode, "lightmap: PBR materials + MOZ_lightmap; emissive: viewable anywhere (baked "
                                           "into emissive)")->capture_default_str()->check(CLI::IsMember({"lightmap", "emissive"}));
    addProbeOptions(*cmd, o->probes, o->probeOptions);
    cmd->add_flag("--progress", o->progress,
                  "Report progress on stderr even when it is not a terminal (then a line a second): each step as it "
                  "begins, the shooting's unshot light and then its local rounds, the lightmaps' direct light and "
                  "texels with the time left, and each stage's summary");
    return [o]() { return runBake(*o); };
}

}  // namespace hemibake::cli
