#include "baker/lightmap/ray_gatherer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <embree3/rtcore.h>
#include <tbb/parallel_for.h>

#include "baker/rays/embree_scene.h"
#include "mesh/frame_math.h"

namespace hemibake {

namespace {

// The two copies of a double-sided surface: same instance, same source face, same three corners (in any order).
struct TwinKey {
    std::uint32_t instance, sourceFace;
    std::array<glm::dvec3, 3> corners;  // sorted
    bool operator==(const TwinKey& o) const {
        return instance == o.instance && sourceFace == o.sourceFace && corners == o.corners;
    }
};
struct TwinKeyHash {
    std::size_t operator()(const TwinKey& k) const {
        std::uint64_t h = splitMix64((std::uint64_t(k.instance) << 32) ^ k.sourceFace);
        for (const glm::dvec3& c : k.corners)
            for (int i = 0; i < 3; ++i) {
                std::uint64_t bits = 0;
                const double v = c[i] == 0.0 ? 0.0 : c[i];  // −0 and +0 hash alike
                std::memcpy(&bits, &v, sizeof bits);
                h = splitMix64(h ^ bits);
            }
        return std::size_t(h);
    }
};

TwinKey twinKey(const ElementArrays& el, std::size_t e) {
    TwinKey k{el.instance[e], el.sourceFace[e], {}};
    for (int c = 0; c < 3; ++c) k.corners[std::size_t(c)] = el.vertices[el.triangles[e][std::size_t(c)]];
    std::sort(k.corners.begin(), k.corners.end(), [](const glm::dvec3& a, const glm::dvec3& b) {
        return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
    });
    return k;
}

// Elements with a coincident, opposite copy (one of a double-sided surface's two sides).
std::vector<std::uint8_t> elementsWithTwins(const ElementArrays& el) {
    std::vector<std::uint8_t> hasTwin(el.size(), 0);
    std::unordered_map<TwinKey, std::uint32_t, TwinKeyHash> fronts;
    for (std::size_t e = 0; e < el.size(); ++e)
        if (!el.backSide[e]) fronts.emplace(twinKey(el, e), std::uint32_t(e));
    for (std::size_t e = 0; e < el.size(); ++e) {
        if (!el.backSide[e]) continue;
        const auto it = fronts.find(twinKey(el, e));
        if (it == fronts.end()) continue;
        hasTwin[e] = 1;
        hasTwin[it->second] = 1;
    }
    return hasTwin;
}

const char* embreeErrorName(RTCError error) {
    switch (error) {
        case RTC_ERROR_NONE: return "no error";
        case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
        case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
        case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
        case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
        case RTC_ERROR_CANCELLED: return "cancelled";
        default: return "unknown error";
    }
}

}  // namespace

// One triangle per element (primID = element index). Coincident twins are both in the BVH; the filter drops the one
// whose back faces the ray, so the other one is found at the same distance.
struct RayGatherer::Embree {
    struct FilterData {
        const std::vector<glm::vec3>* normal;
        const std::vector<std::uint8_t>* hasTwin;
    };

    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    glm::dvec3 origin{0.0};
    std::vector<std::uint8_t> hasTwin;
    FilterData filterData{};

    static void dropTwinBacks(const RTCFilterFunctionNArguments* args) {
        const auto* data = static_cast<const FilterData*>(args->geometryUserPtr);
        for (unsigned i = 0; i < args->N; ++i) {
            if (args->valid[i] != -1) continue;
            const std::uint32_t e = RTCHitN_primID(args->hit, args->N, i);
            if (!(*data->hasTwin)[e]) continue;
            const glm::vec3& n = (*data->normal)[e];
            const float facing = n.x * RTCRayN_dir_x(args->ray, args->N, i) + n.y * RTCRayN_dir_y(args->ray, args->N, i) +
                                 n.z * RTCRayN_dir_z(args->ray, args->N, i);
            if (!(facing < 0.0f)) args->valid[i] = 0;
        }
    }

    void check(const char* what) const {
        const RTCError error = rtcGetDeviceError(device);
        if (error != RTC_ERROR_NONE)
            throw std::runtime_error(std::string("Embree: ") + embreeErrorName(error) + " while " + what + " (ray gather)");
    }

    explicit Embree(const PatchMesh& mesh) {
        const ElementArrays& el = mesh.elements;
        device = rtcNewDevice(nullptr);
        if (!device) throw std::runtime_error(std::string("Embree: cannot create a device: ") + embreeErrorName(rtcGetDeviceError(nullptr)));
        scene = rtcNewScene(device);
        check("creating the scene");
        rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);  // no ray slips between two elements through their shared edge
        glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
        for (const glm::dvec3& v : el.vertices) {
            lo = glm::min(lo, v);
            hi = glm::max(hi, v);
        }
        origin = el.vertices.empty() ? glm::dvec3(0.0) : 0.5 * (lo + hi);
        hasTwin = elementsWithTwins(el);
        filterData = {&el.normal, &hasTwin};
        if (el.size() == 0) {
            rtcCommitScene(scene);
            return;
        }
        RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        check("creating the element geometry");
        auto* positions = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                      3 * sizeof(float), el.vertices.size()));
        auto* indices = static_cast<std::uint32_t*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), el.size()));
        if (!positions || !indices) {
            rtcReleaseGeometry(geometry);
            check("allocating the element buffers");
            throw std::runtime_error("Embree: cannot allocate the element buffers (ray gather)");
        }
        for (std::size_t v = 0; v < el.vertices.size(); ++v) {
            const glm::dvec3 p = el.vertices[v] - origin;
            for (int c = 0; c < 3; ++c) positions[3 * v + std::size_t(c)] = float(p[c]);
        }
        for (std::size_t e = 0; e < el.size(); ++e)
            for (int c = 0; c < 3; ++c) indices[3 * e + std::size_t(c)] = el.triangles[e][std::size_t(c)];
        if (std::find(hasTwin.begin(), hasTwin.end(), 1) != hasTwin.end()) {
            rtcSetGeometryUserData(geometry, &filterData);
            rtcSetGeometryIntersectFilterFunction(geometry, &Embree::dropTwinBacks);
        }
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene, geometry);
        rtcReleaseGeometry(geometry);
        rtcCommitScene(scene);
        check("building the element BVH");
    }

    ~Embree() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

struct RayGatherer::Seen {
    enum Kind { Sky, Front, Back } kind = Sky;
    std::uint32_t element = 0;
    double b1 = 0.0, b2 = 0.0;  // barycentric weights of the element's corners 1 and 2
};

RayGatherer::RayGatherer(const PatchMesh& mesh, int raysPerPoint, std::uint64_t seed)
    : mesh_(mesh), seed_(seed), embree_(std::make_unique<Embree>(mesh)) {
    while ((strata_ + 1) * (strata_ + 1) <= raysPerPoint) ++strata_;
    double diagonal = 0.0;
    if (!mesh.elements.vertices.empty()) {
        glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
        for (const glm::dvec3& v : mesh.elements.vertices) {
            lo = glm::min(lo, v);
            hi = glm::max(hi, v);
        }
        diagonal = glm::length(hi - lo);
    }
    rayOffsetM_ = std::max(EmbreeScene::kRayEpsilonRelative * diagonal, 1e-9);
}

RayGatherer::~RayGatherer() = default;

void RayGatherer::setElementRadiance(std::vector<glm::vec3> radiance) { radiance_ = std::move(radiance); }

void RayGatherer::setTexelLight(std::shared_ptr<const TexelLight> light) { texelLight_ = std::move(light); }

RayGatherer::Seen RayGatherer::trace(const glm::dvec3& origin, const glm::dvec3& dir) const {
    RTCRayHit rh{};
    const glm::dvec3 o = origin - embree_->origin;
    rh.ray.org_x = float(o.x);
    rh.ray.org_y = float(o.y);
    rh.ray.org_z = float(o.z);
    rh.ray.dir_x = float(dir.x);
    rh.ray.dir_y = float(dir.y);
    rh.ray.dir_z = float(dir.z);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = std::numeric_limits<unsigned>::max();
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rtcIntersect1(embree_->scene, &context, &rh);
    Seen s;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return s;
    s.element = rh.hit.primID;
    s.b1 = rh.hit.u;
    s.b2 = rh.hit.v;
    // In float, as the filter decides, so a twin it kept is never counted as a back face.
    const glm::vec3& n = mesh_.elements.normal[s.element];
    s.kind = n.x * rh.ray.dir_x + n.y * rh.ray.dir_y + n.z * rh.ray.dir_z < 0.0f ? Seen::Front : Seen::Back;
    return s;
}

glm::dvec3 RayGatherer::texelLightAt(std::uint32_t e, double b1, double b2) const {
    const TexelLight& light = *texelLight_;
    if (light.atlasSize <= 0 || e >= light.cornerUvLayer.size()) return glm::dvec3(0.0);
    const auto& corner = light.cornerUvLayer[e];
    if (!(corner[0].z >= 0.0f)) return glm::dvec3(0.0);
    const std::size_t layer = std::size_t(corner[0].z);
    if (layer >= light.layers.size()) return glm::dvec3(0.0);
    const double b0 = 1.0 - b1 - b2;
    const glm::dvec2 uv = b0 * glm::dvec2(corner[0]) + b1 * glm::dvec2(corner[1]) + b2 * glm::dvec2(corner[2]);
    // GL_LINEAR with GL_CLAMP_TO_EDGE, as the radiance hemicube samples it.
    const int size = light.atlasSize;
    const double x = uv.x * size - 0.5, y = uv.y * size - 0.5;
    const double fx0 = std::floor(x), fy0 = std::floor(y);
    const double fx = x - fx0, fy = y - fy0;
    const auto clampIndex = [&](double i) { return std::size_t(std::clamp(i, 0.0, double(size - 1))); };
    const std::size_t x0 = clampIndex(fx0), x1 = clampIndex(fx0 + 1.0), y0 = clampIndex(fy0), y1 = clampIndex(fy0 + 1.0);
    const std::vector<glm::vec3>& texels = light.layers[layer];
    const auto at = [&](std::size_t xi, std::size_t yi) { return glm::dvec3(texels[yi * std::size_t(size) + xi]); };
    const glm::dvec3 value = (1.0 - fy) * ((1.0 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1.0 - fx) * at(x0, y1) + fx * at(x1, y1));
    return glm::dvec3(light.scale[e]) * value;
}

void RayGatherer::gather(const std::vector<GatherPoint>& points, glm::vec3 skyRadiance, std::uint64_t sweep,
                         std::vector<glm::dvec3>& irradianceOverPi, std::vector<float>* backfaceFraction,
                         std::span<const std::uint32_t> keys) const {
    if (!keys.empty() && keys.size() != points.size())
        throw std::invalid_argument("RayGatherer::gather: " + std::to_string(keys.size()) + " keys for " +
                                    std::to_string(points.size()) + " points");
    irradianceOverPi.assign(points.size(), glm::dvec3(0.0));
    if (backfaceFraction) backfaceFraction->assign(points.size(), 0.0f);
    const std::uint64_t base = splitMix64(seed_ ^ splitMix64(sweep));
    const bool texelLightOn = texelLight_ && texelLight_->atlasSize > 0;
    const double strata = double(strata_);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 8), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const glm::dvec3 n = glm::normalize(glm::dvec3(points[i].normal));
            if (!std::isfinite(n.x + n.y + n.z)) continue;  // a degenerate receiver sees nothing
            std::uint64_t state = splitMix64(base + (keys.empty() ? std::uint64_t(i) : std::uint64_t(keys[i])));
            const auto uniform = [&state] {
                state = splitMix64(state);
                return double(state >> 11) * 0x1.0p-53;
            };
            // A random rotation about the normal per point: the strata's pattern does not repeat from texel to texel.
            glm::dvec3 t0, b0;
            orthonormalBasis(n, t0, b0);
            const double angle = 2.0 * M_PI * uniform();
            const glm::dvec3 t = std::cos(angle) * t0 + std::sin(angle) * b0, b = glm::cross(n, t);
            const glm::dvec3 origin = points[i].position + rayOffsetM_ * n;
            glm::dvec3 sum(0.0);
            std::uint64_t backs = 0;
            for (int sy = 0; sy < strata_; ++sy)
                for (int sx = 0; sx < strata_; ++sx) {
                    const glm::dvec2 d = concentricDisk((sx + uniform()) / strata, (sy + uniform()) / strata);
                    const double z = std::sqrt(std::max(0.0, 1.0 - glm::dot(d, d)));
                    const glm::dvec3 dir = glm::normalize(d.x * t + d.y * b + z * n);
                    const Seen seen = trace(origin, dir);
                    if (seen.kind == Seen::Sky) {
                        sum += glm::dvec3(skyRadiance);
                    } else if (seen.kind == Seen::Back) {
                        ++backs;
                    } else {
                        if (seen.element < radiance_.size()) sum += glm::dvec3(radiance_[seen.element]);
                        if (texelLightOn) sum += texelLightAt(seen.element, seen.b1, seen.b2);
                    }
                }
            const double rays = strata * strata;
            irradianceOverPi[i] = sum / rays;
            if (backfaceFraction) (*backfaceFraction)[i] = float(double(backs) / rays);
        }
    });
}

}  // namespace hemibake
