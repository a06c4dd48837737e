#include "baker/lightmap/lightmap_settings.h"

#include <algorithm>
#include <stdexcept>

namespace hemibake {

const char* texelModeName(TexelMode mode) { return mode == TexelMode::Gather ? "gather" : "interpolate"; }

TexelMode parseTexelMode(const std::string& name) {
    if (name == "gather") return TexelMode::Gather;
    if (name == "interpolate") return TexelMode::Interpolate;
    throw std::invalid_argument("unknown texel mode '" + name + "' (gather or interpolate)");
}

const char* finalGatherName(FinalGather method) { return method == FinalGather::Rays ? "rays" : "hemicube"; }

FinalGather parseFinalGather(const std::string& name) {
    if (name == "rays") return FinalGather::Rays;
    if (name == "hemicube") return FinalGather::Hemicube;
    throw std::invalid_argument("unknown final gather '" + name + "' (rays or hemicube)");
}

UnwrapSettings unwrapSettingsFor(const LightmapSettings& lightmap) {
    UnwrapSettings u;
    u.texelsPerUnit = lightmap.texelsPerUnit;
    u.maxAtlasSize = lightmap.maxAtlasSize;
    u.paddingTexels = lightmap.paddingTexels;
    u.keepExistingUv = lightmap.keepExistingUv;
    return u;
}

double defaultTexelsPerUnit(const std::string& preset, double sceneDiagonalM) {
    // Small scenes get a fixed number of texels along their diagonal; large ones a floor in texels per metre
    // like common engine defaults (Unity: 40), so a 50 m level is not baked at 40 cm per texel.
    struct Density { const char* preset; double alongDiagonal; double perMetreFloor; };
    constexpr Density kDensity[] = {{"draft", 64, 8}, {"medium", 128, 16}, {"high", 256, 32}, {"ultra", 512, 64}};
    const double diagonal = sceneDiagonalM > 0.0 ? sceneDiagonalM : 1.0;
    for (const Density& d : kDensity)
        if (preset == d.preset) return std::max(d.alongDiagonal / diagonal, d.perMetreFloor);
    return std::max(128.0 / diagonal, 16.0);
}

}  // namespace hemibake
