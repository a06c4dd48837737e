#include "baker/pipeline/bake_report.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "baker/probes/probe_io.h"

namespace hemibake {

namespace {

template <class V>
nlohmann::json vec(const V& v) { return {v.x, v.y, v.z}; }

nlohmann::json convergenceJson(const SolveReport& solve) {
    nlohmann::json history = nlohmann::json::array();
    for (const ConvergenceRecord& r : solve.history.records())
    {
        history.push_back({{"shots", r.shots}, {"seconds", r.seconds}, {"unshotFraction", r.unshotFraction},
                           {"errorBound", r.errorBound}});
        if (r.localBound >= 0.0 && std::isfinite(r.localBound)) history.back()["localBound"] = r.localBound;
        if (r.localRound > 0)
            history.back()["localRound"] = {{"round", r.localRound}, {"patches", r.localRoundPatches},
                                            {"shots", r.localRoundShots}, {"neverShotPatches", r.localNeverShotPatches}};
    }
    return {{"stopReason", solve.stopReason},
            {"shots", solve.shots},
            {"hemicubes", solve.hemicubes},
            {"rowSampling", solve.rowsByRays ? "rays" : "hemicube"},
            {"cachedShots", solve.cachedShots},
            {"unevenShots", solve.unevenShots},
            {"rowRaysTraced", solve.rowRaysTraced},
            {"elementRows", solve.elementRows},
            {"cachedElementRows", solve.cachedElementRows},
            {"localRounds", solve.localRounds},
            {"emittersByRays", solve.emittersByRays},
            {"emitterTrianglesNearOneReceiver", solve.emitterTrianglesNearOneReceiver},
            {"formFactorCacheMiB", double(solve.formFactorCacheBytes) / 1048576.0},
            {"gatherSweeps", solve.gatherSweeps},
            {"implausibleReceivers", solve.implausibleReceivers},
            {"unshotFraction", solve.unshotFraction},
            {"errorBound", solve.errorBound},
            {"localBound", {{"max", solve.localBoundMax}, {"p95", solve.localBoundP95}, {"median", solve.localBoundMedian}}},
            {"ambient", {{"meanIrradianceW", vec(solve.ambientIrradianceMeanW)},
                         {"elementsReached", solve.ambientElements},
                         {"unknownPatches", solve.ambientUnknownPatches}}},
            // The solve's own stages, inside timings.solve.
            {"seconds", {{"prepare", solve.prepareSeconds}, {"direct", solve.directSeconds}, {"shoot", solve.shootSeconds},
                          {"localBound", solve.localBoundSeconds}, {"gather", solve.gatherSeconds}}},
            {"history", history}};
}

nlohmann::json lightmapJson(const LightmapReport& lm) {
    nlohmann::json atlases = nlohmann::json::array(), surfaces = nlohmann::json::array();
    for (const LightmapReport::Atlas& a : lm.atlases) atlases.push_back({{"size", a.size}, {"utilization", a.utilization}});
    double worstSurface = 0.0;
    for (const SurfaceAgreement& s : lm.surfaces) {
        worstSurface = std::max(worstSurface, s.relativeDifference());
        surfaces.push_back({{"node", s.nodeName},
                            {"instance", s.instance},
                            {"texels", s.texels},
                            {"elementMeanIrradianceOverPi", vec(s.elementMean)},
                            {"lightmapMeanIrradianceOverPi", vec(s.lightmapMean)},
                            {"relativeDifference", s.relativeDifference()}});
    }
    const LightmapStats& st = lm.stats;
    return {{"texelsPerUnit", lm.texelsPerUnit},
            {"files", lm.files},
            {"atlases", atlases},
            {"texels", st.texels},
            {"renderedTexels", st.rendered},
            {"renderedFraction", st.renderedFraction()},
            {"renderedWhy", {{"lattice", st.renderedLattice},
                             {"chartEnds", st.renderedChartEnds},
                             {"unsupported", st.renderedUnsupported},
                             {"unsupportedBy", {{"chartEdge", st.renderedUnsupportedBy.chartEdge},
                                                {"insideGeometry", st.renderedUnsupportedBy.insideGeometry},
                                                {"outOfSight", st.renderedUnsupportedBy.outOfSight}}},
                             {"disagreeing", st.renderedDisagreeing}}},
            {"finalGatherRays",
             {{"perTexel", st.gatherRaysPerTexel}, {"traced", st.gatherRaysTraced}, {"escaped", st.gatherRaysEscaped},
              {"stoppedInside", st.gatherStoppedInside}}},
            {"interpolatedTexels", st.interpolated},
            {"besideChartEdges", {{"probed", st.probedBesideChartEdges}, {"interpolated", st.interpolatedBesideChartEdges}}},
            {"seconds", {{"setup", st.seconds.setup},
                         {"direct", st.seconds.direct},
                         {"texelLight", st.seconds.texelLight},
                         {"gather", st.seconds.gather},
                         {"refill", st.seconds.refill},
                         {"gaps", st.seconds.gaps},
                         {"dilateAndSeams", st.seconds.dilateAndSeams}}},
            {"invalidTexels", st.invalid},
            {"dilatedTexels", st.dilated},
            {"gaps", {{"texels", st.gapTexels}, {"passes", st.gapPasses}, {"lastChange", st.gapLastChange}}},
            {"gatherTexelDirect", {{"elements", st.texelDirect.elementsMapped},
                                   {"flatNoTexels", st.texelDirect.elementsNoUv},
                                   {"flatTexelsDisagree", st.texelDirect.elementsDisagree}}},
            {"charts", lm.charts},
            {"surfaceAgreement", {{"maxRelativeDifference", worstSurface}, {"surfaces", surfaces}}},
            {"seams", {{"edges", lm.seams.seamEdges},
                       {"samples", lm.seams.samples},
                       {"maxRelativeBefore", lm.seams.maxRelativeBefore},
                       {"maxRelativeAfter", lm.seams.maxRelativeAfter},
                       {"meanRelativeBefore", lm.seams.meanRelativeBefore},
                       {"meanRelativeAfter", lm.seams.meanRelativeAfter},
                       {"sweeps", lm.seams.sweeps}}}};
}

}  // namespace

nlohmann::json BakeReport::toJson() const {
    nlohmann::json j;
    j["format"] = "hemibake-bake/1";
    j["scene"] = scenePath;
    j["sceneAbsolute"] = sceneAbsolute;
    j["settings"] = hemibake::toJson(settings);
    j["timings"] = nlohmann::json::object();
    for (const StageTiming& t : timings) j["timings"][t.stage] = t.seconds;
    j["timings"]["total"] = totalSeconds;
    j["peakMemoryMiB"] = peakMemoryMiB;
    j["hugePageHeap"] = hugePageHeap;
    j["counts"] = {{"triangles", triangles}, {"patches", patches}, {"elements", elements}, {"islands", islands}};
    j["warnings"] = warnings;
    j["convergence"] = convergenceJson(solve);
    j["power"] = {{"emittedW", vec(solve.emitterPowerW)},
                  {"directW", vec(solve.directPowerW)},
                  {"absorbedW", vec(solve.absorbedPowerW)},
                  {"escapedW", vec(solve.escapedPowerW)},
                  {"backfaceW", vec(solve.backfacePowerW)},
                  {"unshotW", vec(solve.unshotPowerW)}};
    j["solidCuts"] = {{"solids", solidCuts.solids},
                      {"facesCut", solidCuts.facesCut},
                      {"facesCutAtGaps", solidCuts.facesCutAtGaps},
                      {"facesDropped", solidCuts.facesDropped},
                      {"piecesDropped", solidCuts.piecesDropped},
                      {"areaDroppedM2", solidCuts.areaDroppedM2}};
    j["exposedArea"] = {{"elementsTrimmed", exposedArea.elementsTrimmed},
                        {"elementsCovered", exposedArea.elementsCovered},
                        {"areaRemovedM2", exposedArea.areaRemovedM2}};
    j["sides"] = {{"levels", sides.levels},
                  {"regions", sides.regions},
                  {"straddlingElementsLeft", sides.straddlingElementsLeft},
                  {"patchesSplit", sides.patchesSplit},
                  {"patchesAdded", sides.patchesAdded},
                  {"seconds", sides.seconds}};
    j["refinement"] = {{"elementsBefore", refinement.elementsBefore},
                       {"elementsAfter", refinement.elementsAfter},
                       {"regions", refinement.regions},
                       {"roomScale", {{"regions", refinement.roomScale.regions},
                                      {"smallestSizeM", refinement.roomScale.smallestSizeM},
                                      {"medianFreePathM", refinement.roomScale.medianFreePathM}}},
                       {"directSteps", {{"regions", refinement.directSteps.regions},
                                        {"levels", refinement.directSteps.levels},
                                        {"smallestSizeM", refinement.directSteps.smallestSizeM}}}};
    auto draws = [&](const HemicubeDrawTotals& d) {
        const double mean = d.hemicubes ? double(d.triangles) / double(d.hemicubes) : 0.0;
        const double occluders = d.hemicubes ? double(d.occluderTriangles) / double(d.hemicubes) : 0.0;
        return nlohmann::json{{"hemicubes", d.hemicubes},
                              {"occlusionCulledHemicubes", d.occlusionCulledHemicubes},
                              {"meanTrianglesDrawn", mean},
                              {"meanOccluderTriangles", occluders},
                              {"meanFractionOfScene",
                               hemicubeDraws.sceneTriangles ? mean / double(hemicubeDraws.sceneTriangles) : 0.0}};
    };
    j["hemicubeDraws"] = {{"sceneTriangles", hemicubeDraws.sceneTriangles},
                          {"definition", "triangles submitted per hemicube, summed over its five faces, after frustum and "
                                         "occlusion culling, occluder depth pass included (meanOccluderTriangles)"},
                          {"solve", draws(hemicubeDraws.solve)},
                          {"finalGather", draws(hemicubeDraws.finalGather)}};
    if (lightmap) j["lightmap"] = lightmapJson(*lightmap);
    j["primitives"] = nlohmann::json::array();
    for (const BakedPrimitive& p : primitives)
        j["primitives"].push_back({{"node", p.node},
                                   {"mesh", p.mesh},
                                   {"primitive", p.primitive},
                                   {"lightmap", p.lightmap},
                                   {"rect", {p.rect[0], p.rect[1], p.rect[2], p.rect[3]}}});
    if (probes)
        j["probes"] = {{"file", probes->file}, {"count", probes->count}, {"insideGeometry", probes->insideGeometry},
                       {"seconds", probes->seconds}};
    if (volume)
        j["volume"] = {{"file", kVolumeJsonName},
                       {"files", volume->files},
                       {"resolution", vec(volume->resolution)},
                       {"min", vec(volume->min)},
                       {"max", vec(volume->max)},
                       {"probes", volume->probes},
                       {"invalidProbes", volume->invalid},
                       {"relocatedProbes", volume->relocated},
                       {"bytes", volume->bytes},
                       {"seconds", volume->seconds}};
    if (preview)
        j["preview"] = {{"camera", preview->camera}, {"exr", preview->exr}, {"png", preview->png},
                        {"width", preview->width}, {"height", preview->height}};
    return j;
}

bool transparentHugePagesAvailable() {
    std::ifstream kernel("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string line;
    if (!std::getline(kernel, line)) return false;
    return line.find("[always]") != std::string::npos || line.find("[madvise]") != std::string::npos;
}

bool heapInHugePages() {
    const char* tunables = std::getenv("GLIBC_TUNABLES");
    if (tunables == nullptr) return false;
    bool on = false, oneArena = false;
    std::istringstream list(tunables);
    for (std::string item; std::getline(list, item, ':');) {  // the last setting of each counts
        const std::size_t eq = item.find('=');
        const std::string name = item.substr(0, eq), value = eq == std::string::npos ? "" : item.substr(eq + 1);
        if (name == kGlibcHugePageTunable) on = value == "1";
        if (name == kGlibcArenaCountTunable) oneArena = value == "1";
    }
    return on && oneArena && transparentHugePagesAvailable();
}

double peakResidentMemoryMiB() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("VmHWM:", 0) == 0) {
            std::istringstream in(line.substr(6));
            double kib = 0.0;
            in >> kib;
            return kib / 1024.0;
        }
    return 0.0;
}

}  // namespace hemibake
