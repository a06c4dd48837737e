#pragma once
// The probe stage's knobs: light probes at given positions (OUT/probes.json) and the irradiance volume
// (OUT/volume.json + volume.bin), both baked from the solved radiosity (docs/probes.md).
#include <string>

#include "baker/probes/irradiance_volume.h"
#include "baker/probes/light_probes.h"

namespace hemibake {

struct ProbeSettings {
    std::string positionsFile;      // {"positions": [[x,y,z], ...]}; glTF nodes with extras.hemibake_probe add to it
    ProbeBakeSettings probe;        // cube-map resolution (32), SH window, inside-geometry test, depth moments
    bool volume = false;            // bake an irradiance volume
    VolumeGridSettings volumeGrid;  // its box, spacing or resolution, probe relocation
};

}  // namespace hemibake
