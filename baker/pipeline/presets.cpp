#include "baker/pipeline/presets.h"

#include <algorithm>
#include <stdexcept>

#include "mesh/islands.h"

namespace hemibake {

namespace {
// Presets size patches from the scene's bounding-box diagonal up to this diagonal, and no further: a 26 m level and a
// 60 m level get the same patches in metres (medium 3.5 m, a room's width or less). Sizing a 43 m level from its
// own diagonal gave 5.4 m patches that spanned rooms: per object median 5.2 %, worst 12.6 % (issue 15, README
// "Levels"). Scenes smaller than this scale as before (a 1 m Cornell box gets 0.12 m patches at medium).
constexpr double kLargestSizingDiagonalM = 28.0;
// Up to this many times that diagonal (280 m: any level with rooms); beyond it a scene is an open world, sized from a
// tenth of its diagonal so the patch count stays bounded (a 100 km terrain gets 1.8 km patches, not 10⁹ of 3.5 m).
constexpr double kRoomSizedUpTo = 10.0;

// The diagonal the preset fractions apply to.
double sizingDiagonalM(double sceneDiagonalM) {
    if (!(sceneDiagonalM > 0.0)) return 1.0;
    if (sceneDiagonalM <= kLargestSizingDiagonalM) return sceneDiagonalM;
    return std::max(kLargestSizingDiagonalM, sceneDiagonalM / kRoomSizedUpTo);
}

struct PresetTable {
    const char* name;
    double patchPerDiagonal;    // patch size = sizingDiagonalM(diagonal) × this
    double elementPerPatch;     // element size = patch size × this
    int hemicubeResolution;
    double epsilon;
    double proximityFactor;
    int emitterSamples;         // shadow rays per texel towards emissive surfaces
    int latticeStep;            // Elias placement: first hemicubes every latticeStep texels
    int adaptiveLevels;
    double roomFraction;        // elements ≤ this × their mean free path (baker/solve/room_scale.h)
    const char* summary;
};

// Every preset lights texels directly by rays (emitters and punctual lights: exact where unshadowed, sharp
// shadows at texel resolution) and gathers the bounced light with hemicubes at adaptively placed texels; they
// differ in how finely the bounces are solved and gathered. All shoot near-field patches from several points
// (proximity 2): without it a furnace's corners come out 18 % dark at ρ = 0.8. Measured on the Cornell box:
// README "Presets".
constexpr PresetTable kPresets[] = {
    {"draft", 1.0 / 6, 1.0 / 2, 32, 1e-2, 2.0, 64, 8, 0, 1.0,
     "patches ~diagonal/6 (≤ 4.7 m), elements ≤ free path, R=32, 1% unshot bound, 64 shadow rays per texel, gather every 8th texel first"},
    {"medium", 1.0 / 8, 1.0 / 2, 64, 1e-2, 2.0, 256, 4, 0, 1.0,
     "patches ~diagonal/8 (≤ 3.5 m), elements ≤ free path, R=64, 1% unshot bound, 256 shadow rays per texel, gather every 4th texel first"},
    {"high", 1.0 / 12, 1.0 / 2, 128, 1e-3, 2.0, 1024, 2, 0, 1.0 / 2,
     "patches ~diagonal/12 (≤ 2.3 m), elements ≤ free path/2, R=128, 0.1% unshot bound, 1024 shadow rays per texel, gather every 2nd texel first"},
    {"ultra", 1.0 / 16, 1.0 / 2, 256, 1e-4, 2.0, 4096, 1, 1, 1.0 / 3,
     "patches ~diagonal/16 (≤ 1.75 m), elements ≤ free path/3, R=256, 0.01% unshot bound, one adaptive level, 4096 shadow rays, gather every texel"},
};
}  // namespace

const std::vector<PresetDescription>& presetDescriptions() {
    static const std::vector<PresetDescription> list = [] {
        std::vector<PresetDescription> v;
        for (const PresetTable& p : kPresets) v.push_back({p.name, p.summary});
        return v;
    }();
    return list;
}

BakeSettings presetSettings(const std::string& name, double sceneDiagonalM) {
    for (const PresetTable& p : kPresets) {
        if (name != p.name) continue;
        BakeSettings s;
        s.preset = p.name;
        const double diagonal = sizingDiagonalM(sceneDiagonalM);
        s.solve.subdivision.patchSizeM = diagonal * p.patchPerDiagonal;
        s.solve.subdivision.elementSizeM = s.solve.subdivision.patchSizeM * p.elementPerPatch;
        s.solve.solver.hemicubeResolution = p.hemicubeResolution;
        s.solve.solver.epsilon = p.epsilon;
        s.solve.solver.proximityFactor = p.proximityFactor;
        s.solve.solver.gatherSweeps = 0;  // the texel gather is the final gather of the hybrid solver
        s.solve.solver.kind = SolverKind::Hybrid;
        s.solve.adaptive.levels = p.adaptiveLevels;
        s.solve.roomScale.roomFraction = p.roomFraction;
        s.solve.directSteps.levels = 0;  // experimental: worse and 4x slower on level_small (docs/architecture.md)
        s.solve.lighting.emitters = EmitterLighting::Rays;
        s.solve.lighting.emitterSamples = p.emitterSamples;
        s.lightmap.mode = TexelMode::Gather;
        s.lightmap.latticeStep = p.latticeStep;
        return s;
    }
    throw std::invalid_argument("unknown preset '" + name + "' (draft, medium, high or ultra)");
}

double presetSizingDiagonalM(const Scene& scene) { return SceneIslands::ofScene(scene).largestDiagonalM(); }

}  // namespace hemibake
