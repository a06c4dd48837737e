#include "baker/bake_report.h"

#include <fstream>
#include <sstream>

namespace hemibake {

namespace {
nlohmann::json vec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }
nlohmann::json vec(const glm::vec3& v) { return {v.x, v.y, v.z}; }
}  // namespace

nlohmann::json settingsToJson(const BakeSettings& s) {
    return {{"preset", s.preset},
            {"patchSizeM", s.subdivision.patchSizeM},
            {"elementSizeM", s.subdivision.elementSizeM},
            {"emitterPatchSizeM", s.subdivision.emitterPatchSizeM},
            {"solver", solverKindName(s.solver.kind)},
            {"hemicubeResolution", s.solver.hemicubeResolution},
            {"epsilon", s.solver.epsilon},
            {"maxTimeSeconds", s.solver.maxTimeSeconds},
            {"maxShots", s.solver.maxShots},
            {"gatherSweeps", s.solver.gatherSweeps},
            {"maxGatherSweeps", s.solver.maxGatherSweeps},
            {"ambientCorrection", s.solver.ambientCorrection},
            {"proximityFactor", s.solver.proximityFactor},
            {"formFactorCacheMiB", s.solver.formFactorCacheMiB},
            {"threads", s.solver.threads},
            {"seed", s.solver.seed},
            {"adaptiveLevels", s.adaptive.levels},
            {"adaptiveThreshold", s.adaptive.threshold},
            {"skyRadiance", vec(s.lighting.skyRadiance)},
            {"skySamplesPerElement", s.lighting.skySamplesPerElement},
            {"sunAngularDiameterRad", s.lighting.sunAngularDiameterRad},
            {"lightSamplesPerElement", s.lighting.lightSamplesPerElement},
            {"emitters", emitterLightingName(s.lighting.emitters)},
            {"emitterSamples", s.lighting.emitterSamples},
            {"maxRayTracedEmitters", s.lighting.maxRayTracedEmitters}};
}

nlohmann::json BakeReport::toJson() const {
    nlohmann::json j;
    j["format"] = "hemibake-bake/1";
    j["scene"] = scenePath;
    j["settings"] = settingsToJson(settings);
    j["timings"] = nlohmann::json::object();
    double total = 0.0;
    for (const StageTiming& t : timings) {
        j["timings"][t.stage] = t.seconds;
        total += t.seconds;
    }
    j["timings"]["total"] = total;
    j["peakMemoryMiB"] = peakMemoryMiB;
    j["counts"] = {{"triangles", triangles}, {"patches", patches}, {"elements", elements}};
    nlohmann::json history = nlohmann::json::array();
    for (const ConvergenceRecord& r : solve.history.records())
        history.push_back({{"shots", r.shots}, {"seconds", r.seconds}, {"unshotFraction", r.unshotFraction},
                           {"errorBound", r.errorBound}});
    j["convergence"] = {{"stopReason", solve.stopReason},
                        {"shots", solve.shots},
                        {"hemicubes", solve.hemicubes},
                        {"cachedShots", solve.cachedShots},
                        {"emittersByRays", solve.emittersByRays},
                        {"formFactorCacheMiB", double(solve.formFactorCacheBytes) / 1048576.0},
                        {"gatherSweeps", solve.gatherSweeps},
                        {"unshotFraction", solve.unshotFraction},
                        {"errorBound", solve.errorBound},
                        {"ambientRadiosity", vec(solve.ambientRadiosity)},
                        {"history", history}};
    j["power"] = {{"emittedW", vec(solve.emitterPowerW)},
                  {"directW", vec(solve.directPowerW)},
                  {"absorbedW", vec(solve.absorbedPowerW)},
                  {"escapedW", vec(solve.escapedPowerW)},
                  {"backfaceW", vec(solve.backfacePowerW)},
                  {"unshotW", vec(solve.unshotPowerW)}};
    j["primitives"] = nlohmann::json::array();
    for (const BakedPrimitive& p : primitives)
        j["primitives"].push_back({{"node", p.node},
                                   {"mesh", p.mesh},
                                   {"primitive", p.primitive},
                                   {"lightmap", p.lightmap},
                                   {"rect", {p.rect[0], p.rect[1], p.rect[2], p.rect[3]}}});
    for (auto it = extra.begin(); it != extra.end(); ++it) j[it.key()] = it.value();
    return j;
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
