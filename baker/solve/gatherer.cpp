#include "baker/solve/gatherer.h"

#include <tbb/parallel_for.h>

#include "raster/hemicube.h"
#include "raster/hemicube_pool.h"

namespace hemibake {

void Gatherer::setElementRadiance(const std::vector<glm::vec3>& radiance) { pool_.setElementRadiance(radiance); }

void Gatherer::gather(const std::vector<GatherPoint>& points, glm::vec3 skyRadiance, std::uint64_t sweep,
                      std::vector<glm::dvec3>& irradianceOverPi, std::vector<float>* backfaceFraction) {
    irradianceOverPi.assign(points.size(), glm::dvec3(0.0));
    if (backfaceFraction) backfaceFraction->assign(points.size(), 0.0f);
    const std::uint64_t base = (seed_ * 0x9E3779B97F4A7C15ull) ^ (sweep * 0xBF58476D1CE4E5B9ull);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
        HemicubeRenderer& renderer = pool_.local();
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const HemicubeFrame frame =
                HemicubeFrame::randomlyRotated(points[i].position, glm::dvec3(points[i].normal), base + i);
            const RadianceGather g = renderer.gatherRadiance(frame, skyRadiance);
            irradianceOverPi[i] = g.irradianceOverPi;
            if (backfaceFraction) (*backfaceFraction)[i] = float(g.backfaceFraction);
        }
    });
}

std::vector<GatherPoint> elementGatherPoints(const PatchMesh& mesh) {
    std::vector<GatherPoint> points(mesh.elements.size());
    for (std::size_t e = 0; e < points.size(); ++e) points[e] = {mesh.elements.centroid[e], mesh.elements.normal[e]};
    return points;
}

}  // namespace hemibake
