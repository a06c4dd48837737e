#pragma once
// Every knob of a bake, one struct per stage, gathered here. bake.json's "settings" is toJson of this, and
// fromJson reads it back (bake_layout, batch), so a bake is reproducible from its report.
#include <string>

#include <nlohmann/json.hpp>

#include "baker/lightmap/lightmap_settings.h"
#include "baker/output/output_settings.h"
#include "baker/probes/probe_settings.h"
#include "baker/solve/solve_settings.h"

namespace hemibake {

struct BakeSettings {
    std::string preset = "medium";  // the preset the values came from (overrides applied on top)
    SolveSettings solve;            // subdivision, exposure, solver, adaptive refinement, lighting
    LightmapSettings lightmap;
    ProbeSettings probes;
    OutputSettings output;
};

// One flat object, one key per knob (names as in bake.json since format hemibake-bake/1). Thread-safe.
nlohmann::json toJson(const BakeSettings& settings);
// Keys that are missing keep `defaults`' values (older reports). Throws std::invalid_argument naming the key
// when a value has the wrong type or an unknown enum name.
BakeSettings bakeSettingsFromJson(const nlohmann::json& json, const BakeSettings& defaults = {});

}  // namespace hemibake
