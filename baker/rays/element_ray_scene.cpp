#include "baker/rays/element_ray_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include <embree3/rtcore.h>

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
    // A scene without double-sided surfaces has no back sides: no map of every element's corners (ten copies of the
    // tiled level, 0.95 M elements, spent 0.5 CPU s hashing them for nothing).
    if (std::none_of(el.backSide.begin(), el.backSide.end(), [](std::uint8_t b) { return b != 0; })) return hasTwin;
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

}  // namespace

struct ElementRayScene::Embree {
    struct FilterData {
        const std::vector<glm::vec3>* normal;
        const std::vector<std::uint8_t>* hasTwin;
    };

    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    glm::dvec3 origin{0.0};
    double diagonal = 0.0;  // of the elements' bounds
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
            throw std::runtime_error(std::string("Embree: ") + embreeErrorName(error) + " while " + what + " (element rays)");
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
        diagonal = el.vertices.empty() ? 0.0 : glm::length(hi - lo);
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
            throw std::runtime_error("Embree: cannot allocate the element buffers (element rays)");
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

ElementRayScene::ElementRayScene(const PatchMesh& mesh)
    : mesh_(mesh), embree_(std::make_unique<Embree>(mesh)),
      rayOffsetM_(std::max(EmbreeScene::kRayEpsilonRelative * embree_->diagonal, 1e-9)),
      twins_(std::size_t(std::count(embree_->hasTwin.begin(), embree_->hasTwin.end(), 1))) {}

ElementRayScene::~ElementRayScene() = default;

namespace {

// What the packet tracer needs of a ray's origin: one shared, or one per ray.
struct SharedOrigin {
    glm::dvec3 origin;
    const glm::dvec3& operator()(std::size_t) const { return origin; }
};
struct OriginPerRay {
    std::span<const glm::dvec3> origins;
    const glm::dvec3& operator()(std::size_t k) const { return origins[k]; }
};

}  // namespace

void ElementRayScene::trace(const glm::dvec3& origin, std::span<const glm::dvec3> dirs, std::span<ElementHit> hits) const {
    tracePackets(SharedOrigin{origin}, dirs, hits);
}

void ElementRayScene::trace(std::span<const glm::dvec3> origins, std::span<const glm::dvec3> dirs,
                            std::span<ElementHit> hits) const {
    if (origins.size() != dirs.size())
        throw std::invalid_argument("ElementRayScene::trace: origins and directions differ in count");
    tracePackets(OriginPerRay{origins}, dirs, hits);
}

template <class OriginOf>
void ElementRayScene::tracePackets(const OriginOf& originOf, std::span<const glm::dvec3> dirs, std::span<ElementHit> hits) const {
    if (hits.size() != dirs.size()) throw std::invalid_argument("ElementRayScene::trace: hits and directions differ in count");
    constexpr std::size_t kPacket = 16;
    const std::vector<glm::vec3>& normals = mesh_.elements.normal;
    for (std::size_t first = 0; first < dirs.size(); first += kPacket) {
        const std::size_t count = std::min(kPacket, dirs.size() - first);
        alignas(64) RTCRayHit16 packet;
        alignas(64) int valid[kPacket];
        for (std::size_t k = 0; k < kPacket; ++k) {
            valid[k] = k < count ? -1 : 0;
            const std::size_t ray = first + std::min(k, count - 1);
            setPacketRay(packet.ray, k, glm::vec3(originOf(ray) - embree_->origin), dirs[ray], 0.0f,
                         std::numeric_limits<float>::infinity());
            packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        }
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        rtcIntersect16(valid, embree_->scene, &context, &packet);
        for (std::size_t k = 0; k < count; ++k) {
            ElementHit& hit = hits[first + k];
            hit = ElementHit{};
            if (packet.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;
            hit.element = packet.hit.primID[k];
            hit.b1 = packet.hit.u[k];
            hit.b2 = packet.hit.v[k];
            hit.distanceM = packet.ray.tfar[k];
            // In float, as the filter decides, so a twin it kept is never counted as a back face.
            const glm::vec3& n = normals[hit.element];
            hit.kind = n.x * packet.ray.dir_x[k] + n.y * packet.ray.dir_y[k] + n.z * packet.ray.dir_z[k] < 0.0f
                           ? ElementHit::Kind::Front
                           : ElementHit::Kind::Back;
        }
    }
}

}  // namespace hemibake
