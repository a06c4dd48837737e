// `hemibake sample-volume OUT/ x y z nx ny nz`: E/π from a baked irradiance volume at one point and normal, with
// the leak-aware weights of baker/volume_lookup.h (docs/probes.md).
#include <cmath>
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "baker/probes/probe_io.h"
#include "baker/probes/volume_lookup.h"
#include "cli/command.h"

namespace hemibake::cli {

namespace {

struct SampleVolumeOptions {
    std::string outDir;
    std::vector<double> values;  // x y z nx ny nz
    std::string weighting = "visibility";
    double normalBias = VolumeLookupOptions{}.normalBiasPerSpacing;
    bool json = false;
};

int runSampleVolume(const SampleVolumeOptions& o) {
    const glm::dvec3 point(o.values[0], o.values[1], o.values[2]);
    glm::dvec3 normal(o.values[3], o.values[4], o.values[5]);
    const double length = glm::length(normal);
    if (!(length > 0.0) || !std::isfinite(length)) {
        std::cerr << "hemibake: sample-volume: the normal must be a non-zero vector\n";
        return 2;
    }
    normal /= length;
    const IrradianceVolumeData volume = readIrradianceVolume(o.outDir);
    VolumeLookupOptions options;
    options.weighting = o.weighting == "naive"       ? VolumeWeighting::Naive
                        : o.weighting == "trilinear" ? VolumeWeighting::Trilinear
                                                     : VolumeWeighting::Visibility;
    options.normalBiasPerSpacing = o.normalBias;
    const VolumeSample s = sampleIrradianceVolume(volume, point, normal, options);
    if (o.json) {
        const nlohmann::json j = {{"format", "hemibake-volume-sample/1"},
                                  {"position", {point.x, point.y, point.z}},
                                  {"normal", {normal.x, normal.y, normal.z}},
                                  {"weighting", o.weighting},
                                  {"irradianceOverPi", {s.irradianceOverPi.x, s.irradianceOverPi.y, s.irradianceOverPi.z}},
                                  {"probesUsed", s.probesUsed},
                                  {"weightSum", s.weightSum}};
        std::cout << j.dump(2) << "\n";
    } else {
        std::printf("%.6g %.6g %.6g\n", s.irradianceOverPi.x, s.irradianceOverPi.y, s.irradianceOverPi.z);
    }
    if (s.probesUsed == 0) std::cerr << "hemibake: sample-volume: no valid probe around this point; returned 0\n";
    return 0;
}

}  // namespace

CommandRunner addSampleVolumeCommand(CLI::App& app) {
    auto o = std::make_shared<SampleVolumeOptions>();
    CLI::App* cmd = app.add_subcommand(
        "sample-volume", "Print E/π (R G B, W·m⁻²·sr⁻¹) interpolated from OUT/volume.json at a point and normal, with "
                         "visibility-aware weights that keep light from leaking through walls (docs/probes.md)");
    cmd->add_option("out", o->outDir, "Bake output directory holding volume.json (bake with --volume-spacing/--volume-res)")
        ->required();
    cmd->add_option("values", o->values, "x y z nx ny nz: world position (metres) and surface normal")
        ->required()
        ->expected(6);
    cmd->add_option("--weighting", o->weighting,
                    "visibility: trilinear × back-face × depth test (default); trilinear: over valid probes; naive: "
                    "plain trilinear over all eight probes (leaks, for comparison)")
        ->capture_default_str()
        ->check(CLI::IsMember({"visibility", "trilinear", "naive"}));
    cmd->add_option("--normal-bias", o->normalBias,
                    "Depth-test offset along the normal, as a fraction of the smallest probe spacing")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_flag("--json", o->json, "Print a JSON object instead of three numbers");
    return [o]() { return runSampleVolume(*o); };
}

}  // namespace hemibake::cli
