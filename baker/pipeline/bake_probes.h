#pragma once
// The probe stage of the pipeline: light probes (OUT/probes.json) and the irradiance volume (OUT/volume.json +
// volume.bin + volume_visibility.bin), baked from the solved radiosity (docs/probes.md).
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "baker/pipeline/bake_report.h"
#include "baker/probes/probe_settings.h"
#include "baker/solve/solve_scene.h"
#include "mesh/scene.h"

namespace hemibake {

// Probe positions the settings ask for: the positions file, then the scene's "hemibake_probe" nodes. Read before
// the solve so that a bad file fails early. Throws InputError naming the file.
std::vector<glm::dvec3> probePositions(const ProbeSettings& settings, const Scene& scene);

// Bakes and writes into `out` what the settings ask for (probes at `positions`, the volume when
// settings.volume), filling `probes` / `volume`. `progress` gets transient lines and each stage's summary
// (done = true). Throws what the writers throw.
void bakeProbes(const ProbeSettings& settings, const std::vector<glm::dvec3>& positions, const Scene& scene,
                const SolvedScene& solved, glm::vec3 skyRadiance, const std::filesystem::path& out,
                std::optional<ProbesReport>& probes, std::optional<VolumeReport>& volume,
                const std::function<void(const std::string&, bool done)>& progress);

}  // namespace hemibake
