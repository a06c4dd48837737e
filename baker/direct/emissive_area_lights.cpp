#include "baker/direct/emissive_area_lights.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "baker/rays/embree_scene.h"
#include "mesh/frame_math.h"

namespace hemibake {

namespace {

double luminance(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

double unitDouble(std::uint64_t bits) { return double(bits >> 11) * (1.0 / 9007199254740992.0); }

// Sutherland–Hodgman against the plane n·(x − p) ≥ 0: a triangle becomes at most a quadrilateral.
int clipAbove(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3* in, int count, glm::dvec3* out) {
    int k = 0;
    for (int i = 0; i < count; ++i) {
        const glm::dvec3& a = in[i];
        const glm::dvec3& b = in[(i + 1) % count];
        const double da = glm::dot(n, a - p), db = glm::dot(n, b - p);
        if (da >= 0.0) out[k++] = a;
        if ((da >= 0.0) != (db >= 0.0)) out[k++] = a + (b - a) * (da / (da - db));
    }
    return k;
}

}  // namespace

EmissiveAreaLights::EmissiveAreaLights(const PatchMesh& mesh, const EmbreeScene& rays, int samplesPerPoint)
    : rays_(rays), samples_(samplesPerPoint) {
    if (samplesPerPoint < 1) throw std::invalid_argument("EmissiveAreaLights: samplesPerPoint must be at least 1");
    const ElementArrays& el = mesh.elements;
    for (std::size_t e = 0; e < el.size(); ++e) {
        const glm::dvec3 radiance(el.emittedRadiance[e]);
        if (!(radiance.x > 0.0 || radiance.y > 0.0 || radiance.z > 0.0)) continue;
        Triangle t;
        t.a = el.vertices[el.triangles[e][0]];
        t.b = el.vertices[el.triangles[e][1]];
        t.c = el.vertices[el.triangles[e][2]];
        const glm::dvec3 cross = glm::cross(t.b - t.a, t.c - t.a);
        const double twiceArea = glm::length(cross);
        if (!(twiceArea > 0.0)) continue;  // degenerate: emits nothing
        t.normal = cross / twiceArea;
        t.areaM2 = 0.5 * twiceArea;
        t.radiance = radiance;
        triangles_.push_back(t);
    }
}

double EmissiveAreaLights::emittedPowerW() const {
    double sum = 0.0;
    for (const Triangle& t : triangles_) sum += M_PI * (t.radiance.x + t.radiance.y + t.radiance.z) * t.areaM2;
    return sum;
}

double EmissiveAreaLights::unoccludedFormFactor(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3* polygon,
                                                int count) {
    std::array<glm::dvec3, 8> clipped;
    if (count > 6) throw std::invalid_argument("unoccludedFormFactor: at most 6 vertices");
    const int k = clipAbove(p, n, polygon, count, clipped.data());
    if (k < 3) return 0.0;
    double sum = 0.0;
    for (int i = 0; i < k; ++i) {
        const glm::dvec3 a = clipped[i] - p, b = clipped[(i + 1) % k] - p;
        const glm::dvec3 c = glm::cross(a, b);
        const double length = glm::length(c);
        if (!(length > 0.0)) continue;  // an edge through p, or a clipped vertex on p: no angle
        sum += std::atan2(length, glm::dot(a, b)) * glm::dot(n, c) / length;
    }
    return std::max(0.0, std::abs(sum) / (2.0 * M_PI));
}

glm::dvec3 EmissiveAreaLights::irradianceOverPiAt(const glm::dvec3& p, const glm::dvec3& n, std::uint64_t seed) const {
    if (triangles_.empty()) return glm::dvec3(0.0);
    // Unoccluded contribution of each triangle facing p; the sampling distribution follows its luminance.
    thread_local std::vector<double> cdf;
    thread_local std::vector<std::uint32_t> index;
    cdf.clear();
    index.clear();
    glm::dvec3 unoccluded(0.0);
    double total = 0.0;
    for (std::size_t i = 0; i < triangles_.size(); ++i) {
        const Triangle& t = triangles_[i];
        if (!(glm::dot(p - t.a, t.normal) > 0.0)) continue;  // p is behind the emitting side
        const glm::dvec3 v[3] = {t.a, t.b, t.c};
        const double f = unoccludedFormFactor(p, n, v, 3);
        if (!(f > 0.0)) continue;
        unoccluded += f * t.radiance;
        total += f * luminance(t.radiance);
        cdf.push_back(total);
        index.push_back(std::uint32_t(i));
    }
    if (!(total > 0.0)) return glm::dvec3(0.0);

    const glm::dvec3 origin = rays_.offsetFromSurface(p, n);
    glm::dvec3 weighted(0.0), visible(0.0);
    std::uint64_t state = splitMix64(seed);
    for (int s = 0; s < samples_; ++s) {
        const double u = (s + unitDouble(state = splitMix64(state))) / samples_;  // stratified over the CDF
        const std::size_t pick = std::min<std::size_t>(
            std::size_t(std::upper_bound(cdf.begin(), cdf.end(), u * total) - cdf.begin()), cdf.size() - 1);
        const Triangle& t = triangles_[index[pick]];
        const double pdf = (cdf[pick] - (pick ? cdf[pick - 1] : 0.0)) / total;
        double r1 = unitDouble(state = splitMix64(state)), r2 = unitDouble(state = splitMix64(state));
        const double sq = std::sqrt(r1);
        const glm::dvec3 x = (1.0 - sq) * t.a + sq * (1.0 - r2) * t.b + sq * r2 * t.c;
        const glm::dvec3 d = x - p;
        const double dist2 = glm::dot(d, d);
        if (!(dist2 > 0.0) || !(pdf > 0.0)) continue;
        const double cosP = glm::dot(n, d), cosX = -glm::dot(t.normal, d);
        if (cosP <= 0.0 || cosX <= 0.0) continue;  // the clipped-away part of the triangle
        const glm::dvec3 a = t.radiance * (t.areaM2 * cosP * cosX / (dist2 * dist2 * pdf));
        weighted += a;
        if (!rays_.occluded(origin, rays_.offsetFromSurface(x, t.normal), EmbreeScene::RayEnds::Lifted)) visible += a;
    }
    glm::dvec3 result(0.0);
    for (int c = 0; c < 3; ++c)
        result[c] = weighted[c] > 0.0 ? unoccluded[c] * (visible[c] / weighted[c]) : unoccluded[c];
    return result;
}

std::unique_ptr<EmissiveAreaLights> makeEmissiveAreaLights(const PatchMesh& mesh, const EmbreeScene& rays,
                                                           const LightingSettings& lighting, int samplesPerPoint) {
    if (lighting.emitters != EmitterLighting::Rays) return nullptr;
    std::size_t emitting = 0;
    for (const glm::vec3& l : mesh.elements.emittedRadiance) emitting += (l.x > 0.0f || l.y > 0.0f || l.z > 0.0f);
    if (emitting == 0 || emitting > std::size_t(std::max(lighting.maxRayTracedEmitters, 0))) return nullptr;
    return std::make_unique<EmissiveAreaLights>(mesh, rays, samplesPerPoint > 0 ? samplesPerPoint : lighting.emitterSamples);
}

}  // namespace hemibake
