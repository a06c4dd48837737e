#include "baker/pipeline/bake_settings.h"

#include <stdexcept>

namespace hemibake {

namespace {

// The one list of knobs: each is visited by name, so the writer and the reader cannot drift apart. `Enum`
// carries an enum's print/parse pair.
template <class E>
struct Enum {
    E& value;
    const char* (*name)(E);
    E (*parse)(const std::string&);
};

template <class Visitor>
void visitKnobs(BakeSettings& s, Visitor&& v) {
    auto& sub = s.solve.subdivision;
    auto& ex = s.solve.exposure;
    auto& so = s.solve.solver;
    auto& li = s.solve.lighting;
    auto& lm = s.lightmap;
    auto& pr = s.probes;
    auto& out = s.output;
    v("preset", s.preset);
    // Solve: subdivision and exposed areas.
    v("patchSizeM", sub.patchSizeM);
    v("elementSizeM", sub.elementSizeM);
    v("emitterPatchSizeM", sub.emitterPatchSizeM);
    v("cutAlongSolids", sub.cutAlongSolids);
    v("gapCutFraction", sub.gapCutFraction);
    v("exposureSamplesPerSide", ex.samplesPerSide);
    v("exposureScreenSamplesPerSide", ex.screenSamplesPerSide);
    v("exposureRayStrata", ex.rayStrata);
    v("exposureScreenRayStrata", ex.screenRayStrata);
    v("exposureCoveredBackfaceFraction", ex.coveredBackfaceFraction);
    v("exposureHorizonRays", ex.horizonRays);
    v("exposureHorizonElevationRad", ex.horizonElevationRad);
    v("exposureMinFraction", ex.minFraction);
    v("separateSides", s.solve.sides.enabled);
    v("sidesSamplesPerSide", s.solve.sides.samplesPerSide);
    v("sidesMinEdgeFraction", s.solve.sides.minEdgeFraction);
    v("sidesLiftFraction", s.solve.sides.liftFraction);
    v("roomFraction", s.solve.roomScale.roomFraction);
    v("roomScaleRaysPerElement", s.solve.roomScale.raysPerElement);
    v("roomScaleMinSizeFraction", s.solve.roomScale.minSizeFraction);
    v("directStepLevels", s.solve.directSteps.levels);
    v("directStepContrast", s.solve.directSteps.contrast);
    v("directStepSamplesPerSide", s.solve.directSteps.samplesPerSide);
    v("directStepEmitterSamples", s.solve.directSteps.emitterSamples);
    v("directStepFaintFraction", s.solve.directSteps.faintFraction);
    v("directStepMinSizeFraction", s.solve.directSteps.minSizeFraction);
    // Solve: the solver and adaptive refinement.
    v("solver", Enum<SolverKind>{so.kind, solverKindName, parseSolverKind});
    v("hemicubeResolution", so.hemicubeResolution);
    v("rowSampling", Enum<RowSampling>{so.rowSampling, rowSamplingName, parseRowSampling});
    v("rowRays", so.rowRays);
    v("epsilon", so.epsilon);
    v("maxTimeSeconds", so.maxTimeSeconds);
    v("maxShots", so.maxShots);
    v("gatherSweeps", so.gatherSweeps);
    v("maxGatherSweeps", so.maxGatherSweeps);
    v("ambientCorrection", so.ambientCorrection);
    v("proximityFactor", so.proximityFactor);
    v("unevenShotSpread", so.unevenShotSpread);
    v("unevenRaysPerLightShare", so.unevenRaysPerLightShare);
    v("formFactorCacheMiB", so.formFactorCacheMiB);
    v("threads", so.threads);
    v("seed", so.seed);
    v("adaptiveLevels", s.solve.adaptive.levels);
    v("adaptiveThreshold", s.solve.adaptive.threshold);
    // Lighting.
    v("skyRadiance", li.skyRadiance);
    v("skySamplesPerElement", li.skySamplesPerElement);
    v("sunAngularDiameterRad", li.sunAngularDiameterRad);
    v("lightSamplesPerElement", li.lightSamplesPerElement);
    v("emitters", Enum<EmitterLighting>{li.emitters, emitterLightingName, parseEmitterLighting});
    v("emitterSamples", li.emitterSamples);
    v("maxRayTracedEmitters", li.maxRayTracedEmitters);
    // Lightmaps.
    v("texelsPerUnit", lm.texelsPerUnit);
    v("maxAtlasSize", lm.maxAtlasSize);
    v("paddingTexels", lm.paddingTexels);
    v("keepExistingUv", lm.keepExistingUv);
    v("texelMode", Enum<TexelMode>{lm.mode, texelModeName, parseTexelMode});
    v("latticeStep", lm.latticeStep);
    v("finalGather", Enum<FinalGather>{lm.finalGather, finalGatherName, parseFinalGather});
    v("gatherRays", lm.gatherRays);
    v("gatherResolution", lm.gatherResolution);
    v("interpolationTolerance", lm.interpolationTolerance);
    v("invalidBackfaceFraction", lm.invalidBackfaceFraction);
    v("gatherTexelDirect", lm.gatherTexelDirect);
    v("gapPasses", lm.gapPasses);
    v("gapTolerance", lm.gapTolerance);
    v("dilationTexels", lm.dilationTexels);
    v("stitchSeams", lm.stitchSeams);
    v("texelNormalOffsetRelative", lm.texels.normalOffsetRelative);
    v("texelCoverageShrinkTexels", lm.texels.coverageShrinkTexels);
    v("texelBorderInsetTexels", lm.texels.borderInsetTexels);
    // Probes and the irradiance volume.
    v("probesFile", pr.positionsFile);
    v("probeResolution", pr.probe.resolution);
    v("shWindow", Enum<ShWindow>{pr.probe.window, shWindowName, parseShWindow});
    v("probeInsideBackfaceFraction", pr.probe.insideBackfaceFraction);
    v("probeDepthResolution", pr.probe.depthResolution);
    v("probeMaxDepthM", pr.probe.maxDepthM);
    v("volume", pr.volume);
    v("volumeSpacingM", pr.volumeGrid.spacingM);
    v("volumeResolution", pr.volumeGrid.resolution);
    v("volumeBox", pr.volumeGrid.box);
    v("volumeMaxRelocationPerSpacing", pr.volumeGrid.maxRelocationPerSpacing);
    v("volumeRelocationMarginPerSpacing", pr.volumeGrid.relocationMarginPerSpacing);
    // Output.
    v("gltfMode", Enum<GltfWriteOptions::Mode>{out.gltf.mode, gltfModeName, parseGltfMode});
    v("lightmapDir", out.gltf.lightmapDir);
    v("preview", out.preview);
    v("previewWidthPixels", out.previewWidthPixels);
}

struct Writer {
    nlohmann::json& j;
    template <class T>
    void operator()(const char* key, const T& value) { j[key] = value; }
    template <class E>
    void operator()(const char* key, const Enum<E>& e) { j[key] = e.name(e.value); }
    template <class V>
    void operator()(const char* key, const V& v) requires requires { v.x; v.z; } { j[key] = {v.x, v.y, v.z}; }
    void operator()(const char* key, const std::optional<Bounds>& box) {
        j[key] = box ? nlohmann::json{box->min.x, box->min.y, box->min.z, box->max.x, box->max.y, box->max.z}
                     : nlohmann::json(nullptr);
    }
};

struct Reader {
    const nlohmann::json& j;
    template <class T>
    void operator()(const char* key, T& value) {
        if (const auto it = j.find(key); it != j.end()) value = get<T>(key, *it);
    }
    template <class E>
    void operator()(const char* key, Enum<E> e) {
        if (const auto it = j.find(key); it != j.end()) e.value = e.parse(get<std::string>(key, *it));
    }
    template <class V>
    void operator()(const char* key, V& v) requires requires { v.x; v.z; } {
        const auto it = j.find(key);
        if (it == j.end()) return;
        if (!it->is_array() || it->size() != 3) throw std::invalid_argument(std::string("settings.") + key + ": expected 3 numbers");
        for (int i = 0; i < 3; ++i) v[i] = get<typename V::value_type>(key, (*it)[std::size_t(i)]);
    }
    void operator()(const char* key, std::optional<Bounds>& box) {
        const auto it = j.find(key);
        if (it == j.end() || it->is_null()) return;
        if (!it->is_array() || it->size() != 6) throw std::invalid_argument(std::string("settings.") + key + ": expected 6 numbers or null");
        Bounds b;
        for (int i = 0; i < 3; ++i) {
            b.min[i] = get<double>(key, (*it)[std::size_t(i)]);
            b.max[i] = get<double>(key, (*it)[std::size_t(i) + 3]);
        }
        box = b;
    }
    template <class T>
    static T get(const char* key, const nlohmann::json& value) {
        try {
            return value.get<T>();
        } catch (const nlohmann::json::exception& e) {
            throw std::invalid_argument(std::string("settings.") + key + ": " + e.what());
        }
    }
};

}  // namespace

nlohmann::json toJson(const BakeSettings& settings) {
    nlohmann::json j = nlohmann::json::object();
    BakeSettings copy = settings;  // the visitor hands out references for both directions
    visitKnobs(copy, Writer{j});
    return j;
}

BakeSettings bakeSettingsFromJson(const nlohmann::json& json, const BakeSettings& defaults) {
    BakeSettings s = defaults;
    if (!json.is_object()) throw std::invalid_argument("settings: expected an object");
    visitKnobs(s, Reader{json});
    return s;
}

}  // namespace hemibake
