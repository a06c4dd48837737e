#include "baker/direct/sky_light.h"
#include "mesh/frame_math.h"
#include "mesh/triangle_sampling.h"

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include <tbb/parallel_for.h>

namespace hemibake {

namespace {

// A SplitMix64 sequence: jitter reproducible from the seed alone.
double uniform01(std::uint64_t& state) {
    state += 0x9E3779B97F4A7C15ull;
    return double(splitMix64(state - 0x9E3779B97F4A7C15ull) >> 11) * 0x1.0p-53;
}

struct SkyRays {
    int open = 0, back = 0, total = 0;  // escaped, landed on a back face (counted only when asked), traced
};

// Stratified cosine-weighted rays at p (Malley's method). With `countBackHits`, rays are intersected to count
// those that land on back faces too (slower than occlusion rays).
SkyRays sampleSky(const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n, int samples, std::uint64_t seed,
                  bool countBackHits) {
    const int side = std::max(1, int(std::ceil(std::sqrt(double(std::max(samples, 1))))));
    glm::dvec3 t, b;
    orthonormalBasis(n, t, b);
    const glm::dvec3 origin = rays.offsetFromSurface(p, n);
    std::uint64_t state = seed;
    SkyRays count;
    count.total = side * side;
    std::vector<glm::dvec3> dirs;
    dirs.reserve(std::size_t(count.total));
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j) {
            const double u = (i + uniform01(state)) / side, v = (j + uniform01(state)) / side;
            const double r = std::sqrt(u), phi = 2.0 * M_PI * v;
            dirs.push_back(glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0, 1.0 - u)) * n));
        }
    constexpr double kFar = std::numeric_limits<double>::infinity();
    if (!countBackHits) {
        count.open = count.total - int(rays.countOccluded(origin, dirs, kFar, EmbreeScene::RayEnds::Lifted));
        return count;
    }
    for (const glm::dvec3& dir : dirs) {
        const std::optional<Hit> hit = rays.intersect(origin, dir, kFar, EmbreeScene::RayEnds::Lifted);
        if (!hit) ++count.open;
        else if (!hit->frontFacing) ++count.back;
    }
    return count;
}

// skyVisibility at a point of a partly covered element, or nothing when the point is covered: at least half of its
// rays land on back faces (it lies under or inside the cover).
std::optional<double> exposedSkyVisibility(const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n, int samples,
                                           std::uint64_t seed) {
    const SkyRays count = sampleSky(rays, p, n, samples, seed, true);
    if (2 * count.back >= count.total) return std::nullopt;
    return double(count.open) / double(count.total);
}

}  // namespace

double skyVisibility(const EmbreeScene& rays, const glm::dvec3& p, const glm::dvec3& n, int samples, std::uint64_t seed) {
    const SkyRays count = sampleSky(rays, p, n, samples, seed, false);
    return double(count.open) / double(count.total);
}

std::vector<glm::dvec3> elementsSkyIrradianceOverPi(const EmbreeScene& rays, const PatchMesh& mesh, glm::vec3 skyRadiance,
                                                    int samplesPerElement, int pointsPerElement, std::uint64_t seed) {
    std::vector<glm::dvec3> out(mesh.elements.size(), glm::dvec3(0.0));
    if (skyRadiance == glm::vec3(0.0f)) return out;
    const int k = int(std::ceil(std::sqrt(double(std::max(pointsPerElement, 1)))));
    const int raysPerPoint = std::max(1, (std::max(samplesPerElement, 1) + k * k - 1) / (k * k));
    tbb::parallel_for(std::size_t(0), out.size(), [&](std::size_t e) {
        const glm::dvec3 n(mesh.elements.normal[e]);
        const std::uint64_t elementSeed = seed ^ (e * 0xD1B54A32D192ED03ull);
        const bool trimmed = mesh.elements.areaM2[e] < triangleArea(mesh.elements, e) * (1.0 - 1e-9);
        double visible = 0.0;
        int open = 0;
        std::uint64_t point = 0;
        forEachSubTriangleCentroid(k, [&](double wa, double wb) {
            const glm::dvec3 p = pointOnElement(mesh.elements, e, wa, wb);
            const std::uint64_t pointSeed = elementSeed ^ (++point * 0x9E3779B97F4A7C15ull);
            if (!trimmed) {
                visible += skyVisibility(rays, p, n, raysPerPoint, pointSeed);
                ++open;
            } else if (const std::optional<double> v = exposedSkyVisibility(rays, p, n, raysPerPoint, pointSeed)) {
                visible += *v;
                ++open;
            }
        });
        // A trimmed element averages its exposed points only (they stand for its exposed part, what the solver
        // keeps of it); with none of its points exposed, its exposed centroid stands in.
        if (open == 0) visible = skyVisibility(rays, mesh.elements.centroid[e], n, samplesPerElement, elementSeed), open = 1;
        out[e] = visible / double(open) * glm::dvec3(skyRadiance);
    });
    return out;
}

}  // namespace hemibake
