#pragma once
// bake.json ("hemibake-bake/1", CONVENTIONS.md): settings, timings per stage, peak memory, convergence history,
// the power ledger, and one entry per baked primitive.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "baker/bake_settings.h"
#include "baker/radiosity_solver.h"

namespace hemibake {

struct StageTiming {
    std::string stage;
    double seconds = 0.0;
};

struct BakedPrimitive {
    std::string node;       // glTF node name in the output glb
    int mesh = -1;          // mesh index in the output glb
    int primitive = -1;     // primitive index within that mesh
    std::string lightmap;   // EXR path relative to OUT
    int rect[4] = {0, 0, 0, 0};  // x, y, width, height in texels
};

struct BakeReport {
    std::string scenePath;
    BakeSettings settings;
    std::vector<StageTiming> timings;
    double peakMemoryMiB = 0.0;
    std::size_t patches = 0, elements = 0, triangles = 0;
    SolveReport solve;
    std::vector<BakedPrimitive> primitives;
    nlohmann::json extra = nlohmann::json::object();  // later stages add their sections here

    nlohmann::json toJson() const;
};

nlohmann::json settingsToJson(const BakeSettings& settings);

// Peak resident memory of this process so far, MiB (Linux VmHWM).
double peakResidentMemoryMiB();

}  // namespace hemibake
