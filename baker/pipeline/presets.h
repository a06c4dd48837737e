#pragma once
// Presets trade time for accuracy. Sizes scale with the scene's bounding-box diagonal up to a 28 m diagonal and stay
// fixed in metres from there to 280 m (a level's rooms do not grow with the level); beyond, a tenth of the diagonal
// counts (open worlds, bounded patch counts). So the same preset suits a 0.5 m Cornell box, a 60 m level and a
// 100 km terrain; every value can be overridden on the command line.
#include <string>
#include <vector>

#include "baker/pipeline/bake_settings.h"

namespace hemibake {

struct PresetDescription {
    std::string name;
    std::string summary;
};

const std::vector<PresetDescription>& presetDescriptions();
// The settings of preset `name` for a scene of this bounding-box diagonal (metres; ≤ 0 is taken as 1 m).
// Throws std::invalid_argument for an unknown name. Thread-safe.
BakeSettings presetSettings(const std::string& name, double sceneDiagonalM);

}  // namespace hemibake
