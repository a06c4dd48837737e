#pragma once
// `hemibake bake` options and stage for light probes (OUT/probes.json) and the irradiance volume
// (OUT/volume.json + volume.bin + volume_visibility.bin), baked from the solved radiosity (docs/probes.md).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>

#include "baker/bake_report.h"
#include "baker/radiosity_solution.h"
#include "cli/progress.h"
#include "mesh/patches.h"
#include "mesh/scene.h"

namespace hemibake::cli {

struct ProbeOptions {
    std::string probesFile;
    int probeRes = 32;
    std::string shWindow = "none";
    std::optional<double> volumeSpacing;
    std::vector<int> volumeRes;
    std::vector<double> volumeBox;
};

void addProbeOptions(CLI::App& cmd, ProbeOptions& options);

// What the options ask for, with the probe positions file read (so a bad file fails before the solve).
struct ProbeJob {
    std::vector<glm::dvec3> positions;  // from --probes, then the scene's "hemibake_probe" nodes
    bool volume = false;
    bool any() const { return !positions.empty() || volume; }
};
ProbeJob prepareProbeJob(const ProbeOptions& options, const Scene& scene);  // throws InputError, invalid_argument

// Bakes and writes what `job` asks for into `out`, adding "probes" / "volume" sections and timings to `report`.
void runProbeJob(const ProbeJob& job, const ProbeOptions& options, const Scene& scene, const PatchMesh& mesh,
                 const RadiositySolution& solution, glm::vec3 skyRadiance, const std::filesystem::path& out,
                 ProgressLine& progress, BakeReport& report);

}  // namespace hemibake::cli
