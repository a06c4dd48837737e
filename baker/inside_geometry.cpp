#include "baker/inside_geometry.h"
#include "mesh/frame_math.h"

#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

namespace hemibake {

namespace {

// Malley's method: a point of the unit square to a cosine-weighted direction about n (concentric disk mapping).
glm::dvec3 cosineDirection(const glm::dvec3& n, double u1, double u2) {
    const double a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
    double r = 0.0, phi = 0.0;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        phi = M_PI / 4.0 * (b / a);
    } else if (b != 0.0) {
        r = b;
        phi = M_PI / 2.0 - M_PI / 4.0 * (a / b);
    }
    glm::dvec3 t, bt;
    orthonormalBasis(n, t, bt);
    const double z = std::sqrt(std::max(0.0, 1.0 - r * r));
    return glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * bt + z * n);
}

}  // namespace

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
