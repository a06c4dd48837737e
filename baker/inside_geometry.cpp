#include "baker/inside_geometry.h"
#include "mesh/frame_math.h"

#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

namespace hemibake {

std::vector<std::uint8_t> texelsInsideGeometry(const Scene& scene, const EmbreeScene& rays, const AtlasTexels& texels,
                                               double maxBackfaceFraction, int strata) {
    std::vector<std::uint8_t> inside(texels.count(), 0);
    const double total = double(strata) * double(strata);
    tbb::parallel_for(std::size_t(0), texels.count(), [&](std::size_t i) {
        const glm::dvec3 n = glm::normalize(glm::dvec3(texels.normal[i]));
        const glm::dvec3 origin = rays.offsetFromSurface(texels.position[i], n);
        int backfaces = 0;
        for (int v = 0; v < strata; ++v)
            for (int u = 0; u < strata; ++u) {
                const glm::dvec3 dir = cosineDirection(n, (u + 0.5) / strata, (v + 0.5) / strata);
                const auto hit = rays.intersect(origin, dir, std::numeric_limits<double>::infinity(), EmbreeScene::RayEnds::Lifted);
                if (hit && !hit->frontFacing &&
                    !scene.materials[std::size_t(scene.instances[hit->instance].material)].doubleSided)
                    ++backfaces;
            }
        inside[i] = double(backfaces) / total > maxBackfaceFraction;
    });
    return inside;
}

}  // namespace hemibake
