#include "cli/probe_options.h"

namespace hemibake::cli {

void addProbeOptions(CLI::App& cmd, ProbeSettings& s, ProbeOptions& o) {
    cmd.add_option("--probes", s.positionsFile,
                   "Light probes at the positions in this JSON file ({\"positions\": [[x,y,z], ...]}), written to "
                   "OUT/probes.json as L2 SH of incident radiance (glTF nodes with extras.hemibake_probe = true are "
                   "baked too)");
    cmd.add_option("--probe-res", s.probe.resolution, "Cube-map face resolution of each probe, texels")
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

void applyProbeOptions(const ProbeOptions& o, ProbeSettings& s) {
    s.probe.window = parseShWindow(o.shWindow);
    s.volume = o.volumeSpacing.has_value() || !o.volumeRes.empty();
    if (o.volumeSpacing) s.volumeGrid.spacingM = *o.volumeSpacing;
    else if (!o.volumeRes.empty()) s.volumeGrid.resolution = glm::ivec3(o.volumeRes[0], o.volumeRes[1], o.volumeRes[2]);
    if (!o.volumeBox.empty()) {
        Bounds box;
        box.min = glm::dvec3(o.volumeBox[0], o.volumeBox[1], o.volumeBox[2]);
        box.max = glm::dvec3(o.volumeBox[3], o.volumeBox[4], o.volumeBox[5]);
        s.volumeGrid.box = box;
    }
}

}  // namespace hemibake::cli
