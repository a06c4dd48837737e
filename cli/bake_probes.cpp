#include "cli/bake_probes.h"

#include <chrono>
#include <cstdio>
#include <stdexcept>

#include "baker/irradiance_volume.h"
#include "baker/light_probes.h"
#include "baker/probe_io.h"

namespace hemibake::cli {

void addProbeOptions(CLI::App& cmd, ProbeOptions& o) {
    cmd.add_option("--probes", o.probesFile,
                   "Light probes at the positions in this JSON file ({\"positions\": [[x,y,z], ...]}), written to "
                   "OUT/probes.json as L2 SH of incident radiance (glTF nodes with extras.hemibake_probe = true are "
                   "baked too)");
    cmd.add_option("--probe-res", o.probeRes, "Cube-map face resolution of each probe, texels")
        ->capture_default_str()
        ->check(CLI::Range(4, 512));
    cmd.add_option("--sh-window", o.shWindow,
                   "none: exact L2 (rings: -4% lobes behind bright sources); gaussian: bands × (1, 0.830, 0.572), no "
                   "negative lobe but blurred (a uniform sky's E(up) reads 0.915 of the truth)")
        ->capture_default_str()
        ->check(CLI::IsMember({"none", "gaussian"}));
    cmd.add_option("--volume-spacing", o.volumeSpacing,
                   "Irradiance volume: probes at most this far apart (metres) over the scene bounds or --volume-box, "
                   "written to OUT/volume.json + volume.bin")
        ->check(CLI::PositiveNumber);
    cmd.add_option("--volume-res", o.volumeRes, "Irradiance volume: probes per axis nx,ny,nz (each >= 2)")
        ->delimiter(',')
        ->expected(3)
        ->check(CLI::Range(2, 1024));
    cmd.add_option("--volume-box", o.volumeBox, "Irradiance volume box minx,miny,minz,maxx,maxy,maxz (metres; default: "
                                                "the scene bounds)")
        ->delimiter(',')
        ->expected(6);
    // Checked while parsing, so a contradictory command line exits with 2 like any other parse error.
    cmd.parse_complete_callback([&o]() {
        if (o.volumeSpacing && !o.volumeRes.empty())
            throw CLI::ValidationError("--volume-spacing and --volume-res are alternatives; give one");
        if (!o.volumeBox.empty()) {
            if (!o.volumeSpacing && o.volumeRes.empty())
                throw CLI::ValidationError("--volume-box needs --volume-spacing or --volume-res");
            for (int a = 0; a < 3; ++a)
                if (!(o.volumeBox[std::size_t(a)] < o.volumeBox[std::size_t(a) + 3]))
                    throw CLI::ValidationError("--volume-box: min must be below max on every axis");
        }
    });
}

ProbeJob prepareProbeJob(const ProbeOptions& o, const Scene& scene) {
    ProbeJob job;
    if (!o.probesFile.empty()) job.positions = readProbePositions(o.probesFile);
    job.positions.insert(job.positions.end(), scene.probePositions.begin(), scene.probePositions.end());
    job.volume = o.volumeSpacing.has_value() || !o.volumeRes.empty();
    return job;
}

void runProbeJob(const ProbeJob& job, const ProbeOptions& o, const Scene& scene, const PatchMesh& mesh,
                 const RadiositySolution& solution, glm::vec3 skyRadiance, const std::filesystem::path& out,
                 ProgressLine& progress, BakeReport& report) {
    if (!job.any()) return;
    ProbeBakeSettings settings;
    settings.resolution = o.probeRes;
    settings.window = parseShWindow(o.shWindow);
    const std::vector<glm::vec3> radiance = elementOutgoingRadiance(mesh, solution);
    ProbeBaker baker(mesh, radiance, skyRadiance, settings);
    auto lap = [last = std::chrono::steady_clock::now()]() mutable {
        const auto now = std::chrono::steady_clock::now();
        const double s = std::chrono::duration<double>(now - last).count();
        last = now;
        return s;
    };

    if (!job.positions.empty()) {
        progress.update("probes", true);
        std::vector<ProbeRequest> requests;
        for (const glm::dvec3& p : job.positions) requests.push_back(ProbeRequest{p, 0.0, 0.0});
        const std::vector<BakedProbe> probes = baker.bake(requests);
        writeProbesJson(out / "probes.json", probes, settings);
        std::size_t invalid = 0;
        for (const BakedProbe& p : probes) invalid += p.valid ? 0 : 1;
        const double seconds = lap();
        report.timings.push_back({"probes", seconds});
        report.extra["probes"] = {{"file", "probes.json"},     {"count", probes.size()},
                                  {"insideGeometry", invalid}, {"cubeResolution", settings.resolution},
                                  {"shWindow", o.shWindow},    {"seconds", seconds}};
        progress.finish("probes: " + std::to_string(probes.size()) + " written to probes.json" +
                        (invalid ? ", " + std::to_string(invalid) + " inside geometry" : std::string()));
    }
    if (job.volume) {
        VolumeGridSettings grid;
        if (o.volumeSpacing) grid.spacingM = *o.volumeSpacing;
        else grid.resolution = glm::ivec3(o.volumeRes[0], o.volumeRes[1], o.volumeRes[2]);
        if (!o.volumeBox.empty()) {
            Bounds box;
            box.min = glm::dvec3(o.volumeBox[0], o.volumeBox[1], o.volumeBox[2]);
            box.max = glm::dvec3(o.volumeBox[3], o.volumeBox[4], o.volumeBox[5]);
            grid.box = box;
        }
        const VolumeGrid plan = planVolumeGrid(scene.bounds(), grid);
        VolumeBakeStats stats;
        const IrradianceVolumeData volume = bakeIrradianceVolume(baker, plan, grid, stats, [&](std::size_t done, std::size_t total) {
            progress.update("volume: " + std::to_string(done) + " / " + std::to_string(total) + " probes");
        });
        const std::vector<std::string> files = writeIrradianceVolume(out, volume, settings, stats);
        std::uintmax_t bytes = 0;
        for (const std::string& f : files) bytes += std::filesystem::file_size(out / f);
        const double seconds = lap();
        report.timings.push_back({"volume", seconds});
        report.extra["volume"] = {{"file", kVolumeJsonName},
                                  {"files", files},
                                  {"resolution", {plan.resolution.x, plan.resolution.y, plan.resolution.z}},
                                  {"min", {plan.min.x, plan.min.y, plan.min.z}},
                                  {"max", {plan.max.x, plan.max.y, plan.max.z}},
                                  {"probes", stats.probes},
                                  {"invalidProbes", stats.invalid},
                                  {"relocatedProbes", stats.relocated},
                                  {"bytes", bytes},
                                  {"seconds", seconds}};
        char line[160];
        std::snprintf(line, sizeof line, "volume: %dx%dx%d probes (%zu relocated, %zu invalid), %.1f s",
                      plan.resolution.x, plan.resolution.y, plan.resolution.z, stats.relocated, stats.invalid, seconds);
        progress.finish(line);
    }
}

}  // namespace hemibake::cli
