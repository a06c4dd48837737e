#include "baker/rays/inside_geometry.h"
#include "mesh/frame_math.h"

#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

namespace hemibake {

bool rayMeetsBackface(const Scene& scene, const EmbreeScene& rays, const glm::dvec3& origin, const glm::dvec3& dir) {
    const auto hit = rays.intersect(origin, dir, std::numeric_limits<double>::infinity(), EmbreeScene::RayEnds::Lifted);
    return hit && !hit->frontFacing && !scene.materials[std::size_t(scene.instances[hit->instance].material)].doubleSided;
}

namespace {

// Traces the strata × strata rays above p in a fixed order and counts back faces; `stop(backfaces, traced)`
// may end the count early.
template <class Stop>
int countBackfaces(const Scene& scene, const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n, int strata,
                   const Stop& stop) {
    const glm::dvec3 origin = rays.offsetFromSurface(p, n);
    int backfaces = 0, traced = 0;
    for (int v = 0; v < strata; ++v)
        for (int u = 0; u < strata; ++u) {
            const glm::dvec3 dir = cosineDirection(n, (u + 0.5) / strata, (v + 0.5) / strata);
            if (rayMeetsBackface(scene, rays, origin, dir)) ++backfaces;
            if (stop(backfaces, ++traced)) return backfaces;
        }
    return backfaces;
}

}  // namespace

double backfaceFractionAt(const Scene& scene, const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n,
                          int strata) {
    const int backfaces = countBackfaces(scene, rays, p, n, strata, [](int, int) { return false; });
    return double(backfaces) / (double(strata) * double(strata));
}

bool pointInsideGeometry(const Scene& scene, const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n,
                         double maxBackfaceFraction, int strata) {
    const double total = double(strata) * double(strata);
    // Decided once the back faces so far exceed the limit, or once even all remaining rays could not.
    const auto decided = [&](int backfaces, int traced) {
        return double(backfaces) / total > maxBackfaceFraction ||
               !((double(backfaces) + (total - double(traced))) / total > maxBackfaceFraction);
    };
    const int backfaces = countBackfaces(scene, rays, p, n, strata, decided);
    return double(backfaces) / total > maxBackfaceFraction;
}

std::vector<std::uint8_t> texelsInsideGeometry(const Scene& scene, const EmbreeScene& rays, const AtlasTexels& texels,
                                               double maxBackfaceFraction, int strata) {
    std::vector<std::uint8_t> inside(texels.count(), 0);
    tbb::parallel_for(std::size_t(0), texels.count(), [&](std::size_t i) {
        const glm::dvec3 n = glm::normalize(glm::dvec3(texels.normal[i]));
        inside[i] = pointInsideGeometry(scene, rays, texels.position[i], n, maxBackfaceFraction, strata);
    });
    return inside;
}

}  // namespace hemibake
