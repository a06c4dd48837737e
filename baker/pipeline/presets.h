#pragma once
// Presets trade time for accuracy. Sizes scale with the scene's bounding-box diagonal up to a 28 m diagonal and stay
// fixed in metres from there to 280 m (a level's rooms do not grow with the level); beyond, a tenth of the diagonal
// counts (open worlds, bounded patch counts). So the same preset suits a 0.5 m Cornell box, a 60 m level and a
// 100 km terrain; every value can be overridden on the command line. The diagonal is the largest island's
// (mesh/islands.h): copies of a level a kilometre apart are sized as one copy, not as a 3.7 km open world.
#include <string>
#include <vector>

#include "baker/pipeline/bake_settings.h"
#include "mesh/scene.h"

namespace hemibake {

struct PresetDescription {
    std::string name;
    std::string summary;
};

const std::vector<PresetDescription>& presetDescriptions();
// The settings of preset `name` for a scene of this bounding-box diagonal (metres; ≤ 0 is taken as 1 m).
// Throws std::invalid_argument for an unknown name. Thread-safe.
BakeSettings presetSettings(const std::string& name, double sceneDiagonalM);
// The diagonal presets and the default texel density size `scene` by (metres): its largest island's, which is the
// whole scene's when its parts form one island. 0 for a scene without triangles. Thread-safe; visits every vertex.
double presetSizingDiagonalM(const Scene& scene);

}  // namespace hemibake
