#pragma once
// The independent reference: a diffuse-only Monte Carlo path tracer on Embree. It shares the scene model with
// the radiosity baker and nothing else (not even DirectLight's light evaluation), so agreement means something.
//
// Light transport: Lambertian surfaces (ρ from Scene::reflectance at the interpolated TEXCOORD_0), emission L_e
// from the front side only unless the material is double-sided (back faces of single-sided surfaces are black
// absorbers), KHR_lights_punctual lights by next-event estimation with shadow rays, a uniform sky for rays that
// escape. Emissive triangles are reached both by next-event estimation (triangles chosen in proportion to their
// power, points uniform in area) and by cosine-weighted bounces, combined by multiple importance sampling with the
// power heuristic. Russian roulette after `rouletteDepth` bounces. Everything accumulates in double.
//
// Reproducibility: each point/pixel draws from PCG32 streams derived from (seed, stream, chunk of samples), so a
// result depends on the settings and arguments only, never on the thread count or scheduling.
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "baker/rays/embree_scene.h"
#include "baker/util/image.h"
#include "mesh/scene.h"

namespace hemibake {

struct PathTracerSettings {
    glm::vec3 skyRadiance{0.0f};  // L_sky, W·m⁻²·sr⁻¹, seen by bounce rays that escape
    // Path segments after the starting surface point: 1 = direct light only (no interreflection).
    int maxDepth = 64;
    int rouletteDepth = 3;  // bounces before Russian roulette may end a path
    std::uint64_t seed = 1;
    float sunAngularDiameterRad = 0.0f;  // directional lights as disks of this full angle (0 = hard shadows)
    bool useRange = false;               // honour PunctualLight::range (KHR window), as DirectLightSettings
};

struct Estimate {
    glm::dvec3 mean{0.0};
    glm::dvec3 standardError{0.0};  // of the mean, from the sample variance (samples are independent)
    std::uint32_t samples = 0;
    std::uint64_t rays = 0;  // rays traced (bounce + shadow), for throughput figures
};

// A point at which to estimate E/π: position and unit normal of the receiving side.
struct SurfacePoint {
    glm::dvec3 position{0.0};
    glm::vec3 normal{0.0f, 1.0f, 0.0f};
};

// A camera render: linear radiance per pixel and the squared standard error of each pixel's mean.
struct CameraRender {
    RgbImage radiance;        // W·m⁻²·sr⁻¹
    RgbImage varianceOfMean;  // per channel
    std::uint64_t rays = 0;
};

class PathTracer {
public:
    // `scene` and `rays` must outlive this object. Throws std::invalid_argument on bad settings.
    PathTracer(const Scene& scene, const EmbreeScene& rays, PathTracerSettings settings);

    // Texel mode: incident irradiance / π at p on the side n faces, excluding the surface's own emission
    // (what a lightmap texel stores). `stream` selects independent random numbers (e.g. the texel index).
    Estimate irradianceOverPi(const glm::dvec3& p, const glm::vec3& n, std::uint32_t spp, std::uint64_t stream) const;
    // The same for many points in parallel; point i uses stream i.
    std::vector<Estimate> irradianceOverPi(std::span<const SurfacePoint> points, std::uint32_t spp) const;

    // Pinhole camera (vertical field of view yfovRadians, aspect width/height), box-filtered pixels.
    CameraRender renderCamera(const Camera& camera, int width, int height, std::uint32_t spp) const;

    const PathTracerSettings& settings() const { return settings_; }

private:
    struct Emitter {
        glm::dvec3 corner{0.0}, edge1{0.0}, edge2{0.0};
        glm::dvec3 normal{0.0};  // unit, front side
        double areaM2 = 0.0;
        glm::dvec3 radiance{0.0};
        bool doubleSided = false;
        double selectionProbability = 0.0;
    };
    // A scattering point: normal on the side the path is on, reflectance at the point. Bounce and emitter rays
    // leave from rayOrigin (lifted off the surface), and emitter sampling uses that same point for its geometry
    // and MIS densities: otherwise the two strategies would estimate light at points rayEpsilonM() apart, a bias
    // that reaches 1e-3 within millimetres of a wall.
    struct Vertex {
        glm::dvec3 position{0.0};
        glm::dvec3 normal{0.0};
        glm::dvec3 reflectance{0.0};
        glm::dvec3 rayOrigin{0.0};
    };
    class Sampler;

    glm::dvec3 reflectedRadiance(const Vertex& start, Sampler& sampler, std::uint64_t& rays) const;
    glm::dvec3 emitterNee(const Vertex& x, Sampler& sampler, std::uint64_t& rays) const;
    glm::dvec3 punctualNee(const Vertex& x, Sampler& sampler, std::uint64_t& rays) const;
    double emitterPdfSolidAngle(std::uint32_t emitter, const glm::dvec3& from, const glm::dvec3& onEmitter,
                                const glm::dvec3& emitterNormal) const;
    bool surfaceAt(const Hit& hit, Vertex& vertex, glm::dvec3& emittedRadiance) const;
    glm::dvec3 cameraSample(const glm::dvec3& origin, const glm::dvec3& dir, Sampler& sampler, std::uint64_t& rays) const;

    const Scene& scene_;
    const EmbreeScene& rays_;
    PathTracerSettings settings_;
    std::vector<Emitter> emitters_;
    std::vector<double> emitterCdf_;               // cumulative selection probability, last = 1
    std::vector<std::int64_t> firstEmitterOfInstance_;  // -1 when the instance does not emit
};

}  // namespace hemibake
