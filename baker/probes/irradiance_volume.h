#pragma once
// An irradiance volume (Greger et al. 1998) baked from the radiosity solution: a regular grid of SH probes
// over a box, probes at cell corners (CONVENTIONS.md "Irradiance volume"), with visibility data for the
// leak-aware lookup (volume_lookup.h). Probes inside geometry are moved out through their nearest back face
// (at most half a cell) or marked invalid.
#include <optional>

#include "baker/probes/light_probes.h"
#include "baker/probes/volume_lookup.h"
#include "mesh/scene.h"

namespace hemibake {

struct VolumeGridSettings {
    std::optional<Bounds> box;       // default: the scene bounds, inset by kSceneBoundsInsetPerDiagonal
    double spacingM = 0.0;           // > 0: probes at most this far apart (the box is divided evenly)
    glm::ivec3 resolution{0};        // used when spacingM is 0: probes per axis, each ≥ 2
    double maxRelocationPerSpacing = 0.5;      // of the smallest spacing
    double relocationMarginPerSpacing = 0.05;  // how far beyond the back face a moved probe lands
};

// The outermost probes of a scene-bounds grid sit this far (× the scene diagonal) inside the bounds, so they
// see the walls the bounds were fitted to instead of looking along them.
inline constexpr double kSceneBoundsInsetPerDiagonal = 1e-3;

struct VolumeGrid {
    glm::dvec3 min{0.0}, max{0.0};
    glm::ivec3 resolution{0};
};

// The grid for these settings; throws std::invalid_argument on an empty box or a resolution below 2.
VolumeGrid planVolumeGrid(const Bounds& sceneBounds, const VolumeGridSettings& settings);

struct VolumeBakeStats {
    std::size_t probes = 0, invalid = 0, relocated = 0;
};

IrradianceVolumeData bakeIrradianceVolume(ProbeBaker& baker, const VolumeGrid& grid, const VolumeGridSettings& settings,
                                          VolumeBakeStats& stats,
                                          const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace hemibake
