#include "baker/reference/path_tracer.h"
#include "mesh/frame_math.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <tbb/parallel_for.h>

namespace hemibake {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr EmbreeScene::RayEnds kLifted = EmbreeScene::RayEnds::Lifted;  // every path vertex lifts its rays
// Samples per independent random stream; the unit of parallel work inside one estimate.
constexpr std::uint32_t kChunkSamples = 256;

double maxComponent(const glm::dvec3& v) { return std::max({v.x, v.y, v.z}); }

// Welford accumulation, merged with Chan et al.'s formula so chunk results combine in a fixed order.
struct RunningStats {
    double count = 0.0;
    glm::dvec3 mean{0.0}, m2{0.0};
    std::uint64_t rays = 0;

    void add(const glm::dvec3& x) {
        count += 1.0;
        const glm::dvec3 delta = x - mean;
        mean += delta / count;
        m2 += delta * (x - mean);
    }
    void merge(const RunningStats& o) {
        if (o.count == 0.0) return;
        const double n = count + o.count;
        const glm::dvec3 delta = o.mean - mean;
        mean += delta * (o.count / n);
        m2 += o.m2 + delta * delta * (count * o.count / n);
        count = n;
        rays += o.rays;
    }
    Estimate estimate() const {
        Estimate e;
        e.mean = mean;
        e.samples = std::uint32_t(count);
        e.rays = rays;
        if (count > 1.0) e.standardError = glm::sqrt(m2 / (count - 1.0) / count);
        return e;
    }
};

}  // namespace

// PCG32 (O'Neill 2014, pcg32_random_r), one instance per (seed, stream, chunk).
class PathTracer::Sampler {
public:
    Sampler(std::uint64_t seed, std::uint64_t stream, std::uint64_t chunk) {
        const std::uint64_t key = splitMix64(splitMix64(seed) ^ splitMix64(stream) * 3 ^ chunk);
        state_ = 0;
        increment_ = (splitMix64(key) << 1u) | 1u;
        nextBits();
        state_ += key;
        nextBits();
    }
    std::uint32_t nextBits() {
        const std::uint64_t old = state_;
        state_ = old * 6364136223846793005ull + increment_;
        const std::uint32_t xorShifted = std::uint32_t(((old >> 18u) ^ old) >> 27u);
        const std::uint32_t rot = std::uint32_t(old >> 59u);
        return (xorShifted >> rot) | (xorShifted << ((32u - rot) & 31u));
    }
    double uniform() { return double(nextBits()) * (1.0 / 4294967296.0); }  // [0, 1)

private:
    std::uint64_t state_ = 0, increment_ = 0;
};

namespace {

// Runs sampleChunk(chunk, count, stats) over fixed chunks of the spp samples, in parallel, and merges in order.
template <class SampleChunk>
Estimate estimateWith(std::uint32_t spp, const SampleChunk& sampleChunk) {
    const std::uint32_t chunks = (spp + kChunkSamples - 1) / kChunkSamples;
    std::vector<RunningStats> partial(chunks);
    tbb::parallel_for(std::uint32_t(0), chunks, [&](std::uint32_t chunk) {
        const std::uint32_t first = chunk * kChunkSamples;
        sampleChunk(chunk, std::min(kChunkSamples, spp - first), partial[chunk]);
    });
    RunningStats total;
    for (const RunningStats& s : partial) total.merge(s);
    return total.estimate();
}

}  // namespace

PathTracer::PathTracer(const Scene& scene, const EmbreeScene& rays, PathTracerSettings settings)
    : scene_(scene), rays_(rays), settings_(settings) {
    if (settings_.maxDepth < 1) throw std::invalid_argument("PathTracer: maxDepth must be at least 1");
    if (settings_.rouletteDepth < 1) throw std::invalid_argument("PathTracer: rouletteDepth must be at least 1");
    if (!(settings_.sunAngularDiameterRad >= 0.0f && settings_.sunAngularDiameterRad < float(M_PI)))
        throw std::invalid_argument("PathTracer: sunAngularDiameterRad must be in [0, pi)");

    double totalPower = 0.0;
    firstEmitterOfInstance_.assign(scene.instances.size(), -1);
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const Material& material = scene.materials.at(std::size_t(scene.instances[i].material));
        if (!material.isEmissive()) continue;
        firstEmitterOfInstance_[i] = std::int64_t(emitters_.size());
        const SurfaceMesh& mesh = scene.instances[i].mesh;
        for (std::uint32_t f = 0; f < mesh.n_faces(); ++f) {
            const auto& v = rays.triangle(std::uint32_t(i), f);
            auto point = [&](std::uint32_t k) {
                const auto& p = mesh.point(mesh.vertex_handle(v[k]));
                return glm::dvec3(p[0], p[1], p[2]);
            };
            Emitter e;
            e.corner = point(0);
            e.edge1 = point(1) - e.corner;
            e.edge2 = point(2) - e.corner;
            e.normal = rays.faceNormal(std::uint32_t(i), f);
            e.areaM2 = 0.5 * glm::length(glm::cross(e.edge1, e.edge2));
            e.radiance = glm::dvec3(material.emittedRadiance);
            e.doubleSided = material.doubleSided;
            // Choose emitters in proportion to the power they send out (both sides when double-sided).
            e.selectionProbability = e.areaM2 * (e.radiance.x + e.radiance.y + e.radiance.z) * (e.doubleSided ? 2.0 : 1.0);
            totalPower += e.selectionProbability;
            emitters_.push_back(e);
        }
    }
    double cumulative = 0.0;
    for (Emitter& e : emitters_) {
        e.selectionProbability = totalPower > 0.0 ? e.selectionProbability / totalPower : 0.0;
        cumulative += e.selectionProbability;
        emitterCdf_.push_back(cumulative);
    }
    if (!emitterCdf_.empty()) emitterCdf_.back() = 1.0;
}

Estimate PathTracer::irradianceOverPi(const glm::dvec3& p, const glm::vec3& n, std::uint32_t spp, std::uint64_t stream) const {
    // A white Lambertian receiver (ρ = 1) reflects (1/π)∫L cosθ dω = E/π: the texel value, emission excluded.
    const glm::dvec3 normal = glm::normalize(glm::dvec3(n));
    const Vertex start{p, normal, glm::dvec3(1.0), rays_.offsetFromSurface(p, normal)};
    return estimateWith(spp, [&](std::uint32_t chunk, std::uint32_t count, RunningStats& stats) {
        Sampler sampler(settings_.seed, stream, chunk);
        for (std::uint32_t s = 0; s < count; ++s) stats.add(reflectedRadiance(start, sampler, stats.rays));
    });
}

std::vector<Estimate> PathTracer::irradianceOverPi(std::span<const SurfacePoint> points, std::uint32_t spp) const {
    std::vector<Estimate> result(points.size());
    tbb::parallel_for(std::size_t(0), points.size(), [&](std::size_t i) {
        result[i] = irradianceOverPi(points[i].position, points[i].normal, spp, i);
    });
    return result;
}

CameraRender PathTracer::renderCamera(const Camera& camera, int width, int height, std::uint32_t spp) const {
    if (width < 1 || height < 1 || spp < 1) throw std::invalid_argument("PathTracer: image size and spp must be positive");
    CameraRender image{RgbImage(width, height), RgbImage(width, height), 0};

    const glm::dvec3 forward = glm::normalize(glm::dvec3(camera.forward));
    const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(camera.up)));
    const glm::dvec3 up = glm::cross(right, forward);
    const double tanHalfY = std::tan(0.5 * double(camera.yfovRadians));
    const double tanHalfX = tanHalfY * double(width) / double(height);

    std::vector<std::uint64_t> rowRays(std::size_t(height), 0);
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            const std::size_t pixel = std::size_t(y) * std::size_t(width) + std::size_t(x);
            // Pixel streams are offset past any texel stream a caller is likely to use with the same seed.
            const Estimate e = estimateWith(spp, [&](std::uint32_t chunk, std::uint32_t count, RunningStats& stats) {
                Sampler sampler(settings_.seed, (1ull << 48) + pixel, chunk);
                for (std::uint32_t s = 0; s < count; ++s) {
                    const double sx = (2.0 * (x + sampler.uniform()) / width - 1.0) * tanHalfX;
                    const double sy = (1.0 - 2.0 * (y + sampler.uniform()) / height) * tanHalfY;
                    stats.add(cameraSample(camera.position, forward + sx * right + sy * up, sampler, stats.rays));
                }
            });
            image.radiance.pixels[pixel] = glm::vec3(e.mean);
            image.varianceOfMean.pixels[pixel] = glm::vec3(e.standardError * e.standardError);
            rowRays[std::size_t(y)] += e.rays;
        }
    });
    for (std::uint64_t r : rowRays) image.rays += r;
    return image;
}

glm::dvec3 PathTracer::cameraSample(const glm::dvec3& origin, const glm::dvec3& dir, Sampler& sampler, std::uint64_t& rays) const {
    ++rays;
    const std::optional<Hit> hit = rays_.intersect(origin, dir, kInfinity, kLifted);  // a camera is off every surface
    if (!hit) return glm::dvec3(settings_.skyRadiance);
    Vertex vertex;
    glm::dvec3 emitted(0.0);
    if (!surfaceAt(*hit, vertex, emitted)) return glm::dvec3(0.0);
    // The camera ray is not a strategy next-event estimation could have produced: emission counts in full.
    return emitted + reflectedRadiance(vertex, sampler, rays);
}

glm::dvec3 PathTracer::reflectedRadiance(const Vertex& start, Sampler& sampler, std::uint64_t& rays) const {
    glm::dvec3 radiance(0.0);
    glm::dvec3 throughput(1.0);  // path weight up to the current vertex, its reflectance not yet applied
    Vertex x = start;
    for (int depth = 0; depth < settings_.maxDepth; ++depth) {
        if (maxComponent(x.reflectance) > 0.0)  // a black surface needs no shadow rays
            radiance += throughput * x.reflectance * (emitterNee(x, sampler, rays) + punctualNee(x, sampler, rays));

        // Cosine-weighted bounce: BRDF·cos/pdf = (ρ/π)·cosθ / (cosθ/π) = ρ.
        const glm::dvec3 dir = cosineDirection(x.normal, sampler.uniform(), sampler.uniform());
        const double cosX = glm::dot(dir, x.normal);
        throughput *= x.reflectance;
        if (maxComponent(throughput) <= 0.0 || !(cosX > 0.0)) break;
        ++rays;
        const std::optional<Hit> hit = rays_.intersect(x.rayOrigin, dir, kInfinity, kLifted);
        if (!hit) {
            radiance += throughput * glm::dvec3(settings_.skyRadiance);
            break;
        }
        Vertex y;
        glm::dvec3 emitted(0.0);
        if (!surfaceAt(*hit, y, emitted)) break;  // the back of a single-sided surface absorbs
        if (maxComponent(emitted) > 0.0) {
            const std::uint32_t emitter = std::uint32_t(firstEmitterOfInstance_[hit->instance]) + hit->face;
            const double pdfLight = emitterPdfSolidAngle(emitter, x.rayOrigin, y.position, y.normal);
            const double pdfBsdf = cosX / M_PI;
            radiance += throughput * emitted * (pdfBsdf * pdfBsdf / (pdfBsdf * pdfBsdf + pdfLight * pdfLight));
        }
        if (depth + 1 >= settings_.maxDepth) break;
        if (depth + 1 >= settings_.rouletteDepth) {
            const double survival = std::min(1.0, maxComponent(throughput));
            if (sampler.uniform() >= survival) break;
            throughput /= survival;
        }
        x = y;
    }
    return radiance;
}

glm::dvec3 PathTracer::emitterNee(const Vertex& x, Sampler& sampler, std::uint64_t& rays) const {
    if (emitters_.empty()) return glm::dvec3(0.0);
    const double pick = sampler.uniform();
    const std::uint32_t index = std::uint32_t(std::min<std::size_t>(
        std::size_t(std::upper_bound(emitterCdf_.begin(), emitterCdf_.end(), pick) - emitterCdf_.begin()), emitters_.size() - 1));
    const Emitter& e = emitters_[index];
    // Uniform point on the triangle (square-root parameterisation).
    const double su = std::sqrt(sampler.uniform()), v = sampler.uniform();
    const glm::dvec3 y = e.corner + (su * (1.0 - v)) * e.edge1 + (su * v) * e.edge2;

    const glm::dvec3 toY = y - x.rayOrigin;
    const double distance2 = glm::dot(toY, toY);
    if (!(distance2 > 0.0)) return glm::dvec3(0.0);
    const glm::dvec3 dir = toY / std::sqrt(distance2);
    const double cosX = glm::dot(dir, x.normal);
    const double cosY = -glm::dot(dir, e.normal);
    if (cosX <= 0.0 || (cosY <= 0.0 && !e.doubleSided) || cosY == 0.0) return glm::dvec3(0.0);
    ++rays;
    // Both ends lifted: a grazing segment would otherwise end inside the float error of the emitter's plane.
    if (rays_.occluded(x.rayOrigin, rays_.offsetFromSurface(y, cosY > 0.0 ? e.normal : -e.normal), kLifted))
        return glm::dvec3(0.0);
    const double pdfLight = emitterPdfSolidAngle(index, x.rayOrigin, y, e.normal);
    const double pdfBsdf = cosX / M_PI;
    const double weight = pdfLight * pdfLight / (pdfLight * pdfLight + pdfBsdf * pdfBsdf);
    return e.radiance * (cosX / M_PI / pdfLight * weight);
}

double PathTracer::emitterPdfSolidAngle(std::uint32_t emitter, const glm::dvec3& from, const glm::dvec3& onEmitter,
                                        const glm::dvec3& emitterNormal) const {
    const Emitter& e = emitters_[emitter];
    const glm::dvec3 d = onEmitter - from;
    const double distance2 = glm::dot(d, d);
    const double cosY = std::abs(glm::dot(emitterNormal, d)) / std::sqrt(distance2);
    if (!(e.areaM2 > 0.0) || !(cosY > 0.0)) return 0.0;
    return e.selectionProbability / e.areaM2 * distance2 / cosY;
}

glm::dvec3 PathTracer::punctualNee(const Vertex& x, Sampler& sampler, std::uint64_t& rays) const {
    glm::dvec3 irradiance(0.0);  // E in W·m⁻² per channel
    for (const PunctualLight& light : scene_.lights) {
        if (light.type == LightType::Directional) {
            const glm::dvec3 toSun = -glm::normalize(glm::dvec3(light.direction));
            const double cosTheta = glm::dot(toSun, x.normal);
            if (cosTheta <= 0.0) continue;
            glm::dvec3 shadowDir = toSun;
            if (settings_.sunAngularDiameterRad > 0.0f) {
                // One direction uniform in the sun's cone: its visibility is an unbiased estimate of the visible fraction.
                const double cosMax = std::cos(0.5 * double(settings_.sunAngularDiameterRad));
                const double cosT = 1.0 - sampler.uniform() * (1.0 - cosMax);
                const double sinT = std::sqrt(std::max(0.0, 1.0 - cosT * cosT));
                const double phi = 2.0 * M_PI * sampler.uniform();
                glm::dvec3 t, b;
                orthonormalBasis(toSun, t, b);
                shadowDir = cosT * toSun + sinT * (std::cos(phi) * t + std::sin(phi) * b);
                if (glm::dot(shadowDir, x.normal) <= 0.0) continue;
            }
            ++rays;
            if (!rays_.occludedRay(x.rayOrigin, shadowDir, kInfinity, kLifted)) irradiance += glm::dvec3(light.intensity) * cosTheta;
            continue;
        }
        const glm::dvec3 toLight = light.position - x.position;
        const double distance2 = glm::dot(toLight, toLight);
        if (!(distance2 > 0.0)) continue;
        const double distance = std::sqrt(distance2);
        const double cosTheta = glm::dot(toLight, x.normal) / distance;
        if (cosTheta <= 0.0) continue;
        double falloff = 1.0;
        if (light.type == LightType::Spot) {
            // KHR_lights_punctual: t = (cos α − cos outer) / (cos inner − cos outer), clamped, squared.
            const double cosAlpha = -glm::dot(toLight, glm::dvec3(light.direction)) / (distance * glm::length(glm::dvec3(light.direction)));
            const double cosOuter = std::cos(double(light.outerConeAngle));
            const double t = (cosAlpha - cosOuter) / std::max(0.001, std::cos(double(light.innerConeAngle)) - cosOuter);
            falloff = std::pow(std::clamp(t, 0.0, 1.0), 2.0);
        }
        if (settings_.useRange && light.range > 0.0f) {
            const double q = distance / double(light.range);
            falloff *= std::clamp(1.0 - q * q * q * q, 0.0, 1.0);
        }
        if (falloff <= 0.0) continue;
        ++rays;
        if (!rays_.occluded(x.rayOrigin, light.position, kLifted)) irradiance += glm::dvec3(light.intensity) * (cosTheta * falloff / distance2);
    }
    return irradiance / M_PI;
}

bool PathTracer::surfaceAt(const Hit& hit, Vertex& vertex, glm::dvec3& emittedRadiance) const {
    const MeshInstance& instance = scene_.instances[hit.instance];
    const Material& material = scene_.materials[std::size_t(instance.material)];
    if (!hit.frontFacing && !material.doubleSided) return false;
    vertex.position = hit.position;
    vertex.normal = hit.frontFacing ? hit.geometricNormal : -hit.geometricNormal;
    vertex.rayOrigin = rays_.offsetFromSurface(vertex.position, vertex.normal);
    glm::vec2 uv(0.0f);
    if (material.reflectanceTexture >= 0) {
        const auto& v = rays_.triangle(hit.instance, hit.face);
        auto texcoord = [&](std::uint32_t k) {
            const auto t = instance.mesh.texcoord2D(instance.mesh.vertex_handle(v[k]));
            return glm::dvec2(t[0], t[1]);
        };
        const double w0 = 1.0 - hit.barycentrics.x - hit.barycentrics.y;
        uv = glm::vec2(w0 * texcoord(0) + hit.barycentrics.x * texcoord(1) + hit.barycentrics.y * texcoord(2));
    }
    vertex.reflectance = glm::dvec3(scene_.reflectance(instance.material, uv));
    emittedRadiance = glm::dvec3(material.emittedRadiance);
    return true;
}

}  // namespace hemibake
