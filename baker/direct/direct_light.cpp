#include "baker/direct/direct_light.h"
#include "baker/direct/emissive_area_lights.h"
#include "mesh/frame_math.h"
#include "mesh/triangle_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace hemibake {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Shadow rays leave from the lifted point, so surfaces within rayEpsilonM() of it (concave corners) still shadow.
constexpr EmbreeScene::RayEnds kLifted = EmbreeScene::RayEnds::Lifted;

// Stateless hash (PCG output permutation over a mixed key): jitter must depend only on (seed, index) so that
// results do not depend on thread scheduling.
std::uint32_t hash(std::uint32_t a, std::uint32_t b) {
    std::uint64_t x = (std::uint64_t(a) << 32 | b) * 0x9E3779B97F4A7C15ull;
    x ^= x >> 29;
    x *= 0xBF58476D1CE4E5B9ull;
    x ^= x >> 32;
    const std::uint32_t state = std::uint32_t(x) * 747796405u + 2891336453u;
    const std::uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

double unitFloat(std::uint32_t bits) { return double(bits >> 8) * (1.0 / 16777216.0); }

}  // namespace

DirectLight::DirectLight(const Scene& scene, const EmbreeScene& rays, DirectLightSettings settings,
                         const EmissiveAreaLights* areaLights)
    : scene_(scene), rays_(rays), settings_(settings), areaLights_(areaLights) {
    if (!(settings_.sunAngularDiameterRad >= 0.0f && settings_.sunAngularDiameterRad < float(M_PI)))
        throw std::invalid_argument("DirectLight: sunAngularDiameterRad must be in [0, pi)");
    if (settings_.sunSamples < 1) throw std::invalid_argument("DirectLight: sunSamples must be at least 1");
}

glm::dvec3 DirectLight::irradianceOverPiAt(const glm::dvec3& p, const glm::vec3& n, std::uint32_t seed) const {
    return irradianceOverPiAt(p, glm::normalize(glm::dvec3(n)), seed, nullptr);
}

glm::dvec3 DirectLight::irradianceOverPiAt(const glm::dvec3& p, const glm::dvec3& normal, std::uint32_t seed,
                                           const EmissiveAreaLights::ReceiverView* view) const {
    glm::dvec3 sum(0.0);
    if (settings_.punctualLights)
        for (const PunctualLight& light : scene_.lights) sum += fromLight(light, p, normal, seed);
    if (areaLights_) {
        const std::uint64_t areaSeed = std::uint64_t(seed) * 0x9E3779B97F4A7C15ull + 1;
        sum += view ? areaLights_->irradianceOverPiAt(p, normal, areaSeed, *view)
                    : areaLights_->irradianceOverPiAt(p, normal, areaSeed);
    }
    return sum;
}

glm::dvec3 DirectLight::fromLight(const PunctualLight& light, const glm::dvec3& p, const glm::dvec3& n,
                                  std::uint32_t seed) const {
    const glm::dvec3 intensity(light.intensity);
    const glm::dvec3 origin = rays_.offsetFromSurface(p, n);
    if (light.type == LightType::Directional) {
        const glm::dvec3 toSun = -glm::normalize(glm::dvec3(light.direction));
        const double cosTheta = glm::dot(n, toSun);
        if (cosTheta <= 0.0) return glm::dvec3(0.0);
        const double visible = settings_.sunAngularDiameterRad > 0.0f
                                   ? sunVisibility(origin, n, toSun, seed)
                                   : (rays_.occludedRay(origin, toSun, kInfinity, kLifted) ? 0.0 : 1.0);
        return intensity * (cosTheta * visible / M_PI);
    }

    const glm::dvec3 toLight = light.position - p;
    const double distance2 = glm::dot(toLight, toLight);
    if (!(distance2 > 0.0)) return glm::dvec3(0.0);
    const double distance = std::sqrt(distance2);
    const glm::dvec3 l = toLight / distance;
    const double cosTheta = glm::dot(n, l);
    if (cosTheta <= 0.0) return glm::dvec3(0.0);

    double attenuation = 1.0 / distance2;
    if (settings_.useRange && light.range > 0.0f)
        attenuation *= std::clamp(1.0 - std::pow(distance / double(light.range), 4.0), 0.0, 1.0);  // KHR's window
    if (light.type == LightType::Spot) {
        // KHR_lights_punctual reference falloff: linear in cos between the cones, then squared.
        const double cosOuter = std::cos(double(light.outerConeAngle));
        const double scale = 1.0 / std::max(0.001, std::cos(double(light.innerConeAngle)) - cosOuter);
        const double cd = glm::dot(glm::normalize(glm::dvec3(light.direction)), -l);
        const double falloff = std::clamp(cd * scale - cosOuter * scale, 0.0, 1.0);
        attenuation *= falloff * falloff;
    }
    if (attenuation <= 0.0 || rays_.occluded(origin, light.position, kLifted)) return glm::dvec3(0.0);
    return intensity * (cosTheta * attenuation / M_PI);
}

double DirectLight::sunVisibility(const glm::dvec3& origin, const glm::dvec3& n, const glm::dvec3& toSun,
                                  std::uint32_t seed) const {
    const double cosHalfAngle = std::cos(0.5 * double(settings_.sunAngularDiameterRad));
    glm::dvec3 t, b;
    orthonormalBasis(toSun, t, b);
    // A jittered nx × ny grid (sunSamples rounded up to fill it), mapped to equal solid angles of the cone.
    const int nx = int(std::ceil(std::sqrt(double(settings_.sunSamples))));
    const int ny = (settings_.sunSamples + nx - 1) / nx;
    int visible = 0;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const std::uint32_t index = std::uint32_t(j * nx + i);
            const double u = (i + unitFloat(hash(seed, 2 * index))) / nx;
            const double v = (j + unitFloat(hash(seed, 2 * index + 1))) / ny;
            const glm::dvec2 d = concentricDisk(u, v);
            const double r2 = glm::dot(d, d);
            const double cosTheta = 1.0 - r2 * (1.0 - cosHalfAngle);
            const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
            const double r = std::sqrt(r2);
            const glm::dvec3 dir = cosTheta * toSun + (r > 0.0 ? sinTheta / r : 0.0) * (d.x * t + d.y * b);
            // Parts of the disk below the horizon are hidden by the surface itself.
            if (glm::dot(dir, n) > 0.0 && !rays_.occludedRay(origin, dir, kInfinity, kLifted)) ++visible;
        }
    return double(visible) / double(nx * ny);
}

glm::dvec3 DirectLight::elementIrradianceOverPi(const PatchMesh& patches, std::size_t element, int samplesPerElement) const {
    if (samplesPerElement < 1) throw std::invalid_argument("DirectLight: samplesPerElement must be at least 1");
    const ElementArrays& e = patches.elements;
    const auto& tri = e.triangles.at(element);
    const glm::dvec3 a = e.vertices[tri[0]], b = e.vertices[tri[1]], c = e.vertices[tri[2]];
    const glm::dvec3 n = glm::normalize(glm::dvec3(e.normal[element]));
    const int k = int(std::ceil(std::sqrt(double(samplesPerElement))));
    // The emitters far from the element are evaluated once for all its points.
    thread_local EmissiveAreaLights::ReceiverView view;
    if (areaLights_) {
        const glm::dvec3 receiver[3] = {a, b, c};
        areaLights_->viewFrom(receiver, n, view);
    }

    glm::dvec3 sum(0.0);
    std::uint32_t index = 0;
    auto sample = [&](double wa, double wb) {
        const std::uint32_t seed = hash(std::uint32_t(element), index++);
        sum += irradianceOverPiAt(wa * a + wb * b + (1.0 - wa - wb) * c, n, seed, areaLights_ ? &view : nullptr);
    };
    forEachSubTriangleCentroid(k, sample);
    return sum / double(k * k);
}

std::vector<glm::dvec3> elementsIrradianceOverPi(const DirectLight& light, const PatchMesh& patches, int samplesPerElement) {
    std::vector<glm::dvec3> result(patches.elements.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, result.size()), [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t e = range.begin(); e != range.end(); ++e)
            result[e] = light.elementIrradianceOverPi(patches, e, samplesPerElement);
    });
    return result;
}

}  // namespace hemibake
