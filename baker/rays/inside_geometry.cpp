#include "baker/rays/inside_geometry.h"
#include "mesh/frame_math.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <limits>

#include <tbb/parallel_for.h>

namespace hemibake {

bool isSingleSidedBackface(const Scene& scene, const HitSide& side) {
    return side.hit && !side.frontFacing && !scene.materials[std::size_t(scene.instances[side.instance].material)].doubleSided;
}

namespace {

// Traces the strata × strata rays above p (cosineDirection at the strata centres, in that order) and counts back
// faces; `stop(backfaces, traced)` may end the count early. Traced in packets of 16 with the frame built once (the
// same directions, bit for bit); the count and the stop see the rays one by one, so the answer is the one a ray at a
// time gives.
template <class Stop>
int countBackfaces(const Scene& scene, const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n, int strata,
                   const Stop& stop) {
    constexpr std::size_t kPacket = 16;
    const glm::dvec3 origin = rays.offsetFromSurface(p, n);
    glm::dvec3 t, b;
    orthonormalBasis(n, t, b);
    const std::size_t total = std::size_t(strata) * std::size_t(strata);
    std::array<glm::dvec3, kPacket> dirs;
    std::array<HitSide, kPacket> sides;
    int backfaces = 0, traced = 0;
    for (std::size_t first = 0; first < total; first += kPacket) {
        const std::size_t count = std::min(kPacket, total - first);
        for (std::size_t k = 0; k < count; ++k) {
            const std::size_t i = first + k;
            const int u = int(i % std::size_t(strata)), v = int(i / std::size_t(strata));
            dirs[k] = cosineDirection(t, b, n, (u + 0.5) / strata, (v + 0.5) / strata);
        }
        rays.intersectSides(origin, std::span(dirs.data(), count), std::numeric_limits<double>::infinity(),
                            EmbreeScene::RayEnds::Lifted, std::span(sides.data(), count));
        for (std::size_t k = 0; k < count; ++k) {
            if (isSingleSidedBackface(scene, sides[k])) ++backfaces;
            if (stop(backfaces, ++traced)) return backfaces;
        }
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
