#include "baker/pipeline/bake_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <tbb/global_control.h>

#include "baker/lightmap/lightmap_seams.h"
#include "baker/lightmap/surface_agreement.h"
#include "baker/output/baked_scene_view.h"
#include "baker/output/exr_io.h"
#include "baker/output/png_preview.h"
#include "baker/output/radiance_preview.h"
#include "baker/pipeline/bake_probes.h"
#include "baker/pipeline/presets.h"
#include "baker/rays/embree_scene.h"
#include "baker/rays/inside_geometry.h"
#include "baker/util/atomic_output.h"
#include "baker/util/rgb_image.h"
#include "baker/util/stopwatch.h"
#include "raster/hemicube_pool.h"

namespace hemibake {

namespace {

std::string percent(double fraction) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g%%", 100.0 * fraction);
    return buf;
}

// A wall time for a person: "42 s", "3 min 05 s", "1 h 02 min".
std::string duration(double seconds) {
    const long s = std::lround(std::max(seconds, 0.0));
    char buf[48];
    if (s < 60)
        std::snprintf(buf, sizeof buf, "%ld s", s);
    else if (s < 3600)
        std::snprintf(buf, sizeof buf, "%ld min %02ld s", s / 60, s % 60);
    else
        std::snprintf(buf, sizeof buf, "%ld h %02ld min", s / 3600, (s % 3600) / 60);
    return buf;
}

// The stages in order; each step fills its part of the result and times itself (timings do not overlap).
class Pipeline {
public:
    Pipeline(const Scene& scene, const BakeSettings& settings, const BakeOutput& output, const BakeProgress& progress)
        : scene_(scene), output_(output), progress_(progress) {
        BakeReport& r = result_.report;
        r.scenePath = output.scenePath;
        r.sceneAbsolute = output.scenePath.empty()
                              ? std::string()
                              : std::filesystem::absolute(output.scenePath).lexically_normal().string();
        r.settings = resolved(settings, scene);
        r.triangles = scene.triangleCount();
        if (output.loadSeconds > 0.0) r.timings.push_back({"load", output.loadSeconds});
        for (const std::string& w : scene.report.warnings) warn(w);
    }

    BakeResult run() {
        const BakeSettings& s = result_.report.settings;
        std::unique_ptr<tbb::global_control> threadLimit;
        if (s.solve.solver.threads > 0)
            threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                                std::size_t(s.solve.solver.threads));
        const std::vector<glm::dvec3> positions = probePositions(s.probes, scene_);  // a bad file fails before the solve
        step("preparing");
        const EmbreeScene rays(scene_);
        result_.report.islands = rays.islands().size();
        stage("setup");
        solve(rays);
        probes(positions);
        unwrap();
        lightmaps(rays);
        write(rays);
        preview();
        BakeReport& r = result_.report;
        r.totalSeconds = output_.loadSeconds + total_.seconds();
        r.peakMemoryMiB = peakResidentMemoryMiB();
        r.hugePageHeap = heapInHugePages();
        if (!output_.dir.empty()) writeTextAtomically(output_.dir / "bake.json", r.toJson().dump(2) + "\n");
        return std::move(result_);
    }

private:
    static BakeSettings resolved(BakeSettings s, const Scene& scene) {
        const int r = s.solve.solver.hemicubeResolution;
        if (r < 2 || r % 2) throw std::invalid_argument("--hemicube-res must be an even number >= 2");
        const int g = s.lightmap.gatherResolution;
        if (g != 0 && (g < 2 || g % 2)) throw std::invalid_argument("--gather-res must be 0 or an even number >= 2");
        if (s.lightmap.gatherRays < 0 || s.lightmap.gatherRays > kMaxGatherRays)
            throw std::invalid_argument("--gather-rays must be 0 (R squared) or 1 ... " + std::to_string(kMaxGatherRays));
        // The islands cost a pass over every vertex: computed only when no density was given.
        if (!(s.lightmap.texelsPerUnit > 0.0))
            s.lightmap.texelsPerUnit = defaultTexelsPerUnit(s.preset, presetSizingDiagonalM(scene));
        return s;
    }

    void send(BakeProgressEvent::Kind kind, const std::string& message) {
        if (progress_ && !progress_({kind, message})) throw BakeCancelled();
    }
    void update(const std::string& message) { send(BakeProgressEvent::Kind::Update, message); }
    void step(const std::string& message) { send(BakeProgressEvent::Kind::Step, message); }
    void done(const std::string& message) { send(BakeProgressEvent::Kind::StageDone, message); }
    void warn(const std::string& message) {
        result_.report.warnings.push_back(message);
        send(BakeProgressEvent::Kind::Warning, message);
    }
    void stage(const char* name) { result_.report.timings.push_back({name, clock_.lap()}); }

    void solve(const EmbreeScene& rays) {
        const SolveSettings& s = result_.report.settings.solve;
        result_.solved = solveScene(scene_, s, rays, [&](const std::string& stage, const ConvergenceRecord& r) {
            if (stage.rfind("preparing", 0) == 0) return step(stage);
            std::string line = stage + ": ";
            if (stage == "shoot" && r.localBound >= 0.0) {
                // Rounds shrink as the phase goes. The worst element's bound is ∞ while a lit patch has never shot
                // (nothing is known of where its light goes), and can be huge for an element lit by a sliver: shown
                // only once it is a figure a person can compare with the stop rule.
                line += std::to_string(r.shots) + " shots, local round " + std::to_string(r.localRound) + ": " +
                        std::to_string(r.localRoundShots) + " / " +
                        std::to_string(r.localRoundPatches) + " patches shot";
                if (r.localNeverShotPatches > 0)
                    line += " (" + std::to_string(r.localNeverShotPatches) + " never shot before)";
                else if (std::isfinite(r.localBound) && r.localBound <= 10.0)
                    line += ", worst element " + percent(r.localBound) + " from its light (stop at " +
                            percent(s.solver.epsilon) + ")";
            } else if (stage == "shoot")
                line += std::to_string(r.shots) + " shots, unshot " + percent(r.unshotFraction) + " of injected (bulk until " +
                        percent(s.solver.epsilon) + ")";
            else
                line += "sweep done, error bound " + percent(r.errorBound);
            char t[32];
            std::snprintf(t, sizeof t, ", %.1f s", r.seconds);
            update(line + t);
        });
        const SolvedScene& solved = *result_.solved;
        BakeReport& report = result_.report;
        report.solve = solved.report;
        report.patches = solved.mesh.patches.size();
        report.elements = solved.mesh.elements.size();
        report.hemicubeDraws.sceneTriangles = solved.mesh.elements.size();
        if (solved.pool) report.hemicubeDraws.solve = solved.pool->drawTotals();
        report.solidCuts = solved.mesh.solidCuts;
        report.exposedArea = solved.exposedArea;
        report.sides = solved.sides;
        report.refinement = {solved.elementsBeforeRefinement, solved.mesh.elements.size(), solved.refinementRegions,
                             solved.roomScale, solved.directSteps};
        if (s.lighting.emitters == EmitterLighting::Rays && !solved.report.emittersByRays &&
            solved.report.emitterTrianglesNearOneReceiver > 0)
            warn(std::to_string(solved.report.emitterTrianglesNearOneReceiver) + " emitter input triangles lie near one "
                 "receiver, more than --max-ray-traced-emitters " + std::to_string(s.lighting.maxRayTracedEmitters) +
                 ": emitters shoot their light like other patches instead of being traced by rays (their shadows "
                 "follow the element grid)");
        stage("solve");
        const SolveReport& sr = solved.report;
        done("solved: " + sr.stopReason + ", " + std::to_string(sr.shots) + " shots, " + std::to_string(sr.gatherSweeps) +
             " gather sweeps, unshot " + percent(sr.unshotFraction) + ", error bound " + percent(sr.errorBound));
    }

    // Probes and the irradiance volume see the solved elements (displayRadiosity / π) and the sky.
    void probes(const std::vector<glm::dvec3>& positions) {
        const BakeSettings& s = result_.report.settings;
        BakeReport& r = result_.report;
        bakeProbes(s.probes, positions, scene_, *result_.solved, s.solve.lighting.skyRadiance, output_.dir, r.probes, r.volume,
                   [&](const std::string& line, bool finished) { finished ? done(line) : update(line); });
        clock_.lap();  // the probe stages timed themselves
        if (r.probes) r.timings.push_back({"probes", r.probes->seconds});
        if (r.volume) r.timings.push_back({"volume", r.volume->seconds});
    }

    void unwrap() {
        const LightmapSettings& s = result_.report.settings.lightmap;
        step("unwrapping");
        result_.atlas = unwrapScene(scene_, unwrapSettingsFor(s));
        result_.texels = computeTexels(scene_, result_.atlas, s.texels);
        for (const std::string& w : result_.atlas.warnings) warn(w);
        stage("unwrap");
    }

    // Bake E/π per texel, dilate, then stitch seams. Dilation first: bilinear taps at a seam reach into the padding,
    // so stitching must see (and adjust) the final padding values, or dilating afterwards would reopen the seams.
    void lightmaps(const EmbreeScene& rays) {
        const BakeSettings& s = result_.report.settings;
        LightmapReport& lm = result_.report.lightmap.emplace();
        // Final gathers at their own resolution render through a pool of their own (new contexts and uploads: a
        // second or two); the solve's pool, and what it drew, is done with.
        SolvedScene& solved = *result_.solved;
        HemicubeDrawTotals drawnBefore = result_.report.hemicubeDraws.solve;
        const int gatherResolution = s.lightmap.gatherResolution;
        if (s.lightmap.mode == TexelMode::Gather && s.lightmap.finalGather == FinalGather::Hemicube && solved.pool &&
            gatherResolution > 0 && gatherResolution != solved.pool->resolution()) {
            solved.pool = std::make_unique<HemicubePool>(solved.mesh, gatherResolution);
            drawnBefore = {};
        }
        // The time left in each phase at its rate since its first report. Gathered texels cost far more than
        // interpolated ones and are not spread evenly over the atlases, so the texels' estimate is rough: on the 100k
        // level at 16 texels/m it ran up to a fifth short (direct light's was right to the second).
        struct PhaseClock {
            LightmapPhase phase{};
            std::size_t firstDone = 0;
            double firstSeconds = -1.0;
        } phaseClock;
        const Stopwatch lightmapClock;
        const auto report = [&](LightmapPhase phase, std::size_t doneTexels, std::size_t total) {
            const double now = lightmapClock.seconds();
            if (phaseClock.firstSeconds < 0.0 || phaseClock.phase != phase) phaseClock = {phase, doneTexels, now};
            std::string line = std::string("lightmaps: ") + (phase == LightmapPhase::DirectLight ? "direct light, " : "") +
                               std::to_string(doneTexels) + " / " + std::to_string(total) + " texels, " + duration(now);
            const double rate = double(doneTexels - phaseClock.firstDone) / std::max(now - phaseClock.firstSeconds, 1e-9);
            if (doneTexels < total && now - phaseClock.firstSeconds >= 1.0 && rate > 0.0)
                line += ", about " + duration(double(total - doneTexels) / rate) + " left";
            update(line);
        };
        result_.lightmaps = bakeLightmaps(scene_, solved, result_.atlas, result_.texels, rays, s.lightmap, s.solve,
                                          lm.stats, report);
        if (solved.pool) {
            HemicubeDrawTotals gather = solved.pool->drawTotals();
            gather -= drawnBefore;
            result_.report.hemicubeDraws.finalGather = gather;
        }
        const Stopwatch padding;
        for (LightmapImage& image : result_.lightmaps) lm.stats.dilated += dilate(image, s.lightmap.dilationTexels);
        lm.seams = stitchSeams(scene_, result_.atlas, result_.lightmaps, s.lightmap.stitchSeams);
        lm.stats.seconds.dilateAndSeams = padding.seconds();
        stage("lightmaps");
    }

    // Per-surface agreement with the elements, then the EXR/PNG lightmaps and the lightmapped glb.
    void write(const EmbreeScene& rays) {
        const BakeSettings& s = result_.report.settings;
        LightmapReport& lm = *result_.report.lightmap;
        step("comparing each surface's texels with its elements");
        std::vector<std::vector<std::uint8_t>> insideGeometry;
        for (const AtlasTexels& t : result_.texels)
            insideGeometry.push_back(texelsInsideGeometry(scene_, rays, t, s.lightmap.invalidBackfaceFraction));
        lm.surfaces = compareSurfaceMeans(scene_, result_.solved->mesh, result_.solved->solution, result_.texels,
                                          result_.lightmaps, insideGeometry);
        lm.texelsPerUnit = s.lightmap.texelsPerUnit;
        lm.charts = result_.atlas.stats.charts;
        if (!output_.dir.empty()) step("writing " + std::to_string(result_.lightmaps.size()) + " lightmap(s) and the glb");
        for (std::size_t a = 0; a < result_.lightmaps.size(); ++a) {
            const std::string rel = lightmapRelativePath(s.output.gltf, int(a));
            if (!output_.dir.empty()) {
                writeLightmapExr(output_.dir / rel, result_.lightmaps[a]);
                writeLightmapPreviewPng((output_.dir / rel).replace_extension(".png"), result_.lightmaps[a]);
            }
            lm.files.push_back(rel);
            lm.atlases.push_back({result_.lightmaps[a].size, result_.atlas.atlases[a].utilization});
        }
        if (!output_.dir.empty()) {
            const std::string stem = std::filesystem::path(output_.scenePath).stem().string();
            result_.report.primitives = writeLightmappedGlb(output_.scenePath, scene_, result_.atlas, result_.lightmaps,
                                                            output_.dir / (stem + ".glb"), s.output.gltf);
        }
        stage("write");
        done("lightmaps: " + std::to_string(result_.lightmaps.size()) + " atlas(es), " + std::to_string(lm.stats.texels) +
             " texels, " + percent(lm.stats.renderedFraction()) + " gathered by " +
             (s.lightmap.mode == TexelMode::Gather ? finalGatherName(s.lightmap.finalGather) : "none") + ", max seam step " +
             percent(lm.seams.maxRelativeBefore) + " -> " + percent(lm.seams.maxRelativeAfter));
    }

    // A picture of the result from the scene's own camera: what the user would look at first.
    void preview() {
        const OutputSettings& s = result_.report.settings.output;
        if (scene_.cameras.empty() || !s.preview || output_.dir.empty()) return;
        step("preview render");
        const Camera& camera = scene_.cameras.front();
        const int height = imageHeightFor(camera, s.previewWidthPixels);
        const RgbImage image = renderBakedScene(scene_, result_.atlas, result_.lightmaps, camera, s.previewWidthPixels, height,
                                                result_.report.settings.solve.lighting.skyRadiance);
        writeRgbExr(output_.dir / "preview.exr", image);
        writeRadiancePreviewPng(output_.dir / "preview.png", image);
        result_.report.preview = PreviewReport{camera.name, "preview.exr", "preview.png", image.width, image.height};
        stage("preview");
    }

    const Scene& scene_;
    const BakeOutput& output_;
    const BakeProgress& progress_;
    BakeResult result_;
    Stopwatch total_, clock_;
};

}  // namespace

BakeResult bakeScene(const Scene& scene, const BakeSettings& settings, const BakeOutput& output, const BakeProgress& progress) {
    return Pipeline(scene, settings, output, progress).run();
}

}  // namespace hemibake
