#include "baker/probes/irradiance_volume.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hemibake {

VolumeGrid planVolumeGrid(const Bounds& sceneBounds, const VolumeGridSettings& settings) {
    VolumeGrid grid;
    if (settings.box) {
        grid.min = settings.box->min;
        grid.max = settings.box->max;
    } else {
        if (sceneBounds.empty()) throw std::invalid_argument("irradiance volume: the scene is empty");
        const double inset = kSceneBoundsInsetPerDiagonal * sceneBounds.diagonal();
        grid.min = sceneBounds.min + inset;
        grid.max = sceneBounds.max - inset;
    }
    const glm::dvec3 extent = grid.max - grid.min;
    if (!(extent.x > 0.0 && extent.y > 0.0 && extent.z > 0.0))
        throw std::invalid_argument("irradiance volume: the box must have positive size on every axis");
    if (settings.spacingM > 0.0) {
        for (int a = 0; a < 3; ++a)
            grid.resolution[a] = std::max(2, int(std::ceil(extent[a] / settings.spacingM - 1e-9)) + 1);
    } else {
        grid.resolution = settings.resolution;
    }
    if (grid.resolution.x < 2 || grid.resolution.y < 2 || grid.resolution.z < 2)
        throw std::invalid_argument("irradiance volume: at least 2 probes per axis are needed");
    const double probes = double(grid.resolution.x) * grid.resolution.y * grid.resolution.z;
    if (probes > 4e6)
        throw std::invalid_argument("irradiance volume: " + std::to_string(std::llround(probes)) +
                                    " probes is too many (at most 4 million)");
    return grid;
}

IrradianceVolumeData bakeIrradianceVolume(ProbeBaker& baker, const VolumeGrid& grid, const VolumeGridSettings& settings,
                                          VolumeBakeStats& stats,
                                          const std::function<void(std::size_t, std::size_t)>& progress) {
    IrradianceVolumeData volume;
    volume.boxMin = grid.min;
    volume.boxMax = grid.max;
    volume.resolution = grid.resolution;
    const glm::dvec3 spacing = volume.spacing();
    const double minSpacing = std::min({spacing.x, spacing.y, spacing.z});
    std::vector<ProbeRequest> requests(volume.probeCount());
    for (int z = 0; z < grid.resolution.z; ++z)
        for (int y = 0; y < grid.resolution.y; ++y)
            for (int x = 0; x < grid.resolution.x; ++x)
                requests[volume.index(x, y, z)] = ProbeRequest{volume.gridPosition(x, y, z),
                                                               settings.maxRelocationPerSpacing * minSpacing,
                                                               settings.relocationMarginPerSpacing * minSpacing};
    const std::vector<BakedProbe> probes = baker.bake(requests, progress);

    const int d = baker.settings().depthResolution;
    volume.depthResolution = d;
    volume.sh.resize(probes.size());
    volume.valid.resize(probes.size());
    volume.probeOffsets.resize(probes.size());
    volume.depthMoments.reserve(probes.size() * std::size_t(d) * std::size_t(d));
    stats = VolumeBakeStats{probes.size(), 0, 0};
    for (std::size_t i = 0; i < probes.size(); ++i) {
        volume.sh[i] = probes[i].sh;
        volume.valid[i] = probes[i].valid ? 1 : 0;
        volume.probeOffsets[i] = glm::vec3(probes[i].position - probes[i].requestedPosition);
        volume.depthMoments.insert(volume.depthMoments.end(), probes[i].depthMoments.begin(), probes[i].depthMoments.end());
        stats.invalid += probes[i].valid ? 0 : 1;
        stats.relocated += probes[i].relocated ? 1 : 0;
    }
    volume.validate();
    return volume;
}

}  // namespace hemibake
