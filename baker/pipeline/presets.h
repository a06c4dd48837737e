#pragma once
// Presets trade time for accuracy. Sizes scale with the scene (its bounding-box diagonal), so the same preset
// suits a 0.5 m Cornell box and a 50 m level; every value can be overridden on the command line.
#include <string>
#include <vector>

#include "baker/pipeline/bake_settings.h"

namespace hemibake {

struct PresetDescription {
    std::string name;
    std::string summary;
};

const std::vector<PresetDescription>& presetDescriptions();
// Throws std::invalid_argument for an unknown name.
BakeSettings presetSettings(const std::string& name, double sceneDiagonalM);

}  // namespace hemibake
