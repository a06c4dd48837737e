#pragma once
// `hemibake bake` options for light probes and the irradiance volume, bound to ProbeSettings (docs/probes.md).
#include <optional>
#include <vector>

#include <CLI/CLI.hpp>

#include "baker/probes/probe_settings.h"

namespace hemibake::cli {

struct ProbeOptions {
    std::string shWindow = "none";
    std::optional<double> volumeSpacing;
    std::vector<int> volumeRes;
    std::vector<double> volumeBox;
};

// Registers the options; contradictory combinations fail while parsing (exit 2).
void addProbeOptions(CLI::App& cmd, ProbeSettings& settings, ProbeOptions& options);
// Moves what the parsed options say into `settings`.
void applyProbeOptions(const ProbeOptions& options, ProbeSettings& settings);

}  // namespace hemibake::cli
