#include "baker/pipeline/bake_probes.h"

#include <cstdio>

#include "baker/probes/irradiance_volume.h"
#include "baker/probes/light_probes.h"
#include "baker/probes/probe_io.h"
#include "baker/util/stopwatch.h"

namespace hemibake {

std::vector<glm::dvec3> probePositions(const ProbeSettings& settings, const Scene& scene) {
    std::vector<glm::dvec3> positions;
    if (!settings.positionsFile.empty()) positions = readProbePositions(settings.positionsFile);
    positions.insert(positions.end(), scene.probePositions.begin(), scene.probePositions.end());
    return positions;
}

void bakeProbes(const ProbeSettings& settings, const std::vector<glm::dvec3>& positions, const Scene& scene,
                const SolvedScene& solved, glm::vec3 skyRadiance, const std::filesystem::path& out,
                std::optional<ProbesReport>& probesReport, std::optional<VolumeReport>& volumeReport,
                const std::function<void(const std::string&, bool done)>& progress) {
    if (positions.empty() && !settings.volume) return;
    const std::vector<glm::vec3> radiance = elementOutgoingRadiance(solved.mesh, solved.solution);
    ProbeBaker baker(solved.mesh, radiance, skyRadiance, settings.probe);
    Stopwatch clock;

    if (!positions.empty()) {
        progress("probes", false);
        std::vector<ProbeRequest> requests;
        for (const glm::dvec3& p : positions) requests.push_back(ProbeRequest{p, 0.0, 0.0});
        const std::vector<BakedProbe> probes = baker.bake(requests);
        if (!out.empty()) writeProbesJson(out / "probes.json", probes, settings.probe);
        ProbesReport& r = probesReport.emplace();
        r.file = "probes.json";
        r.count = probes.size();
        for (const BakedProbe& p : probes) r.insideGeometry += p.valid ? 0 : 1;
        r.seconds = clock.lap();
        progress("probes: " + std::to_string(r.count) + " written to probes.json" +
                     (r.insideGeometry ? ", " + std::to_string(r.insideGeometry) + " inside geometry" : std::string()),
                 true);
    }
    if (settings.volume) {
        const VolumeGrid plan = planVolumeGrid(scene.bounds(), settings.volumeGrid);
        VolumeBakeStats stats;
        const IrradianceVolumeData volume =
            bakeIrradianceVolume(baker, plan, settings.volumeGrid, stats, [&](std::size_t done, std::size_t total) {
                progress("volume: " + std::to_string(done) + " / " + std::to_string(total) + " probes", false);
            });
        VolumeReport& r = volumeReport.emplace();
        if (!out.empty()) {
            r.files = writeIrradianceVolume(out, volume, settings.probe, stats);
            for (const std::string& f : r.files) r.bytes += std::filesystem::file_size(out / f);
        }
        r.resolution = plan.resolution;
        r.min = plan.min;
        r.max = plan.max;
        r.probes = stats.probes;
        r.invalid = stats.invalid;
        r.relocated = stats.relocated;
        r.seconds = clock.lap();
        char line[160];
        std::snprintf(line, sizeof line, "volume: %dx%dx%d probes (%zu relocated, %zu invalid), %.1f s", plan.resolution.x,
                      plan.resolution.y, plan.resolution.z, stats.relocated, stats.invalid, r.seconds);
        progress(line, true);
    }
}

}  // namespace hemibake
