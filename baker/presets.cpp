#include "baker/presets.h"

#include <stdexcept>

namespace hemibake {

namespace {
struct PresetTable {
    const char* name;
    double patchPerDiagonal;    // patch size = diagonal × this
    double elementPerPatch;     // element size = patch size × this
    int hemicubeResolution;
    double epsilon;
    int gatherSweeps;
    int adaptiveLevels;
    const char* summary;
};

constexpr PresetTable kPresets[] = {
    // gatherSweeps are element-level sweeps; presets that gather at every lightmap texel need none (the texel
    // gather is the final gather of the hybrid solver).
    {"draft", 1.0 / 6, 1.0 / 2, 64, 1e-2, 0, 0, "patches ~diagonal/6, R=64, 1% unshot bound, texels from elements"},
    {"medium", 1.0 / 8, 1.0 / 2, 128, 1e-3, 0, 0, "patches ~diagonal/8, R=128, 0.1% unshot bound, adaptive texel gather"},
    {"high", 1.0 / 12, 1.0 / 2, 256, 1e-3, 0, 1, "patches ~diagonal/12, R=256, 0.1% bound, one adaptive level, texel gather"},
    {"ultra", 1.0 / 16, 1.0 / 2, 256, 1e-4, 0, 2, "patches ~diagonal/16, R=256, 0.01% bound, two adaptive levels, texel gather"},
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
        const double diagonal = sceneDiagonalM > 0.0 ? sceneDiagonalM : 1.0;
        s.subdivision.patchSizeM = diagonal * p.patchPerDiagonal;
        s.subdivision.elementSizeM = s.subdivision.patchSizeM * p.elementPerPatch;
        s.solver.hemicubeResolution = p.hemicubeResolution;
        s.solver.epsilon = p.epsilon;
        s.solver.gatherSweeps = p.gatherSweeps;
        s.solver.kind = SolverKind::Hybrid;
        s.adaptive.levels = p.adaptiveLevels;
        // The draft preset fills texels from the element solution; the others gather at every texel that needs it.
        s.lightmap.mode = std::string(p.name) == "draft" ? TexelMode::Interpolate : TexelMode::Gather;
        return s;
    }
    throw std::invalid_argument("unknown preset '" + name + "' (draft, medium, high or ultra)");
}

}  // namespace hemibake
