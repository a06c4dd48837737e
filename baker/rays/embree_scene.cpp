#include "baker/rays/embree_scene.h"
#include "mesh/surface_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hemibake {

namespace {

struct GeometryDeleter {
    void operator()(RTCGeometryTy* geometry) const { rtcReleaseGeometry(geometry); }
};


glm::dvec3 unitDirection(const glm::dvec3& dir) {
    const double length = glm::length(dir);
    if (!(length > 0.0) || !std::isfinite(length)) throw std::invalid_argument("EmbreeScene: ray direction is zero or not finite");
    return dir / length;
}

// Rays first.. of `unitDirs` (at most 16) into `packet` from `origin` (scene frame), the unused lanes invalid and
// repeating the last ray; returns how many are valid.
std::size_t fillPacket(RTCRay16& packet, int (&valid)[16], const glm::vec3& origin, std::span<const glm::dvec3> unitDirs,
                       std::size_t first, double tMin, double tMax) {
    const std::size_t count = std::min<std::size_t>(16, unitDirs.size() - first);
    for (std::size_t k = 0; k < 16; ++k) {
        valid[k] = k < count ? -1 : 0;
        setPacketRay(packet, k, origin, unitDirs[first + std::min(k, count - 1)], float(tMin), float(tMax));
    }
    return count;
}

}  // namespace

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

void EmbreeScene::DeviceDeleter::operator()(RTCDeviceTy* device) const { rtcReleaseDevice(device); }
void EmbreeScene::SceneDeleter::operator()(RTCSceneTy* scene) const { rtcReleaseScene(scene); }

EmbreeScene::EmbreeScene(const Scene& scene) : scene_(&scene), islands_(SceneIslands::ofScene(scene)) {
    const Bounds bounds = scene.bounds();
    origin_ = bounds.empty() ? glm::dvec3(0.0) : bounds.centre();
    islandEpsilonM_.assign(std::max<std::size_t>(islands_.size(), 1), 1e-9);
    for (std::size_t k = 0; k < islands_.size(); ++k)
        islandEpsilonM_[k] = std::max(islands_.lengthM(k, kRayEpsilonRelative, kRayEpsilonFloatSteps), 1e-9);
    rayEpsilonM_ = *std::max_element(islandEpsilonM_.begin(), islandEpsilonM_.end());

    device_.reset(rtcNewDevice(nullptr));
    if (!device_) throw std::runtime_error(std::string("Embree: cannot create a device: ") + embreeErrorName(rtcGetDeviceError(nullptr)));
    rtcScene_.reset(rtcNewScene(device_.get()));
    checkDevice("creating the scene");
    // Robust mode keeps rays through shared triangle edges from slipping between the two triangles.
    rtcSetSceneFlags(rtcScene_.get(), RTC_SCENE_FLAG_ROBUST);

    triangles_.resize(scene.instances.size());
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const SurfaceMesh& mesh = scene.instances[i].mesh;
        InstanceTriangles& tris = triangles_[i];
        tris.vertices.reserve(mesh.n_faces());
        tris.normals.reserve(mesh.n_faces());
        for (auto f : mesh.all_faces()) {
            std::array<std::uint32_t, 3> v{0, 0, 0};
            glm::dvec3 normal(0.0);
            // A deleted face keeps its index as a degenerate triangle, which Embree never reports.
            if (!mesh.status(f).deleted()) {
                int k = 0;
                for (auto vh : mesh.fv_range(f)) v[std::size_t(k++)] = std::uint32_t(vh.idx());
                const glm::dvec3 p0 = toGlm(mesh.point(mesh.vertex_handle(v[0])));
                const glm::dvec3 c = glm::cross(toGlm(mesh.point(mesh.vertex_handle(v[1]))) - p0,
                                                toGlm(mesh.point(mesh.vertex_handle(v[2]))) - p0);
                if (glm::length(c) > 0.0) normal = glm::normalize(c);
            }
            tris.vertices.push_back(v);
            tris.normals.push_back(normal);
        }
        if (mesh.n_faces() == 0 || mesh.n_vertices() == 0) continue;

        std::unique_ptr<RTCGeometryTy, GeometryDeleter> geometry(rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_TRIANGLE));
        checkDevice("creating a triangle geometry");
        auto* positions = static_cast<float*>(rtcSetNewGeometryBuffer(geometry.get(), RTC_BUFFER_TYPE_VERTEX, 0,
                                                                      RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.n_vertices()));
        auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
            geometry.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), mesh.n_faces()));
        checkDevice("allocating geometry buffers");
        for (auto vh : mesh.all_vertices()) {
            const glm::dvec3 p = toGlm(mesh.point(vh)) - origin_;
            for (int c = 0; c < 3; ++c) positions[3 * std::size_t(vh.idx()) + std::size_t(c)] = float(p[c]);
        }
        for (std::size_t f = 0; f < tris.vertices.size(); ++f)
            for (std::size_t c = 0; c < 3; ++c) indices[3 * f + c] = tris.vertices[f][c];
        rtcCommitGeometry(geometry.get());
        rtcAttachGeometryByID(rtcScene_.get(), geometry.get(), unsigned(i));
        checkDevice("attaching a geometry");
    }
    rtcCommitScene(rtcScene_.get());
    checkDevice("building the BVH");
}

EmbreeScene::~EmbreeScene() = default;
EmbreeScene::EmbreeScene(EmbreeScene&&) noexcept = default;
EmbreeScene& EmbreeScene::operator=(EmbreeScene&&) noexcept = default;

void EmbreeScene::checkDevice(const char* what) const {
    const RTCError error = rtcGetDeviceError(device_.get());
    if (error != RTC_ERROR_NONE) throw std::runtime_error(std::string("Embree: ") + embreeErrorName(error) + " while " + what);
}

RTCRay EmbreeScene::makeRay(const glm::dvec3& origin, const glm::dvec3& unitDir, double tNearM, double tFarM) const {
    const glm::dvec3 o = origin - origin_;
    RTCRay ray{};
    ray.org_x = float(o.x);
    ray.org_y = float(o.y);
    ray.org_z = float(o.z);
    ray.dir_x = float(unitDir.x);
    ray.dir_y = float(unitDir.y);
    ray.dir_z = float(unitDir.z);
    ray.tnear = float(tNearM);
    ray.tfar = float(tFarM);
    ray.mask = std::numeric_limits<unsigned>::max();
    return ray;
}

bool EmbreeScene::occluded(const glm::dvec3& from, const glm::dvec3& to, RayEnds ends) const {
    const glm::dvec3 d = to - from;
    const double length = glm::length(d);
    if (ends == RayEnds::Lifted) return length > 0.0 && occludedRay(from, d / length, length, ends);
    const double startM = rayEpsilonAtM(from), endM = rayEpsilonAtM(to);
    if (!(length > startM + endM)) return false;
    return occludedRay(from, d / length, length - endM, ends);
}

bool EmbreeScene::occludedRay(const glm::dvec3& origin, const glm::dvec3& dir, double tMaxM, RayEnds start) const {
    const double tMin = start == RayEnds::Lifted ? 0.0 : rayEpsilonAtM(origin);
    if (!(tMaxM > tMin)) return false;
    RTCRay ray = makeRay(origin, unitDirection(dir), tMin, tMaxM);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rtcOccluded1(rtcScene_.get(), &context, &ray);
    return ray.tfar < 0.0f;  // Embree marks an occluded ray with tfar = -inf
}

std::size_t EmbreeScene::countOccluded(const glm::dvec3& origin, std::span<const glm::dvec3> unitDirs, double tMaxM,
                                       RayEnds start) const {
    const double tMin = start == RayEnds::Lifted ? 0.0 : rayEpsilonAtM(origin);
    if (!(tMaxM > tMin)) return 0;
    constexpr std::size_t kPacket = 16;
    const glm::vec3 o(origin - origin_);
    std::size_t occluded = 0;
    for (std::size_t first = 0; first < unitDirs.size(); first += kPacket) {
        alignas(64) RTCRay16 packet;
        alignas(64) int valid[kPacket];
        const std::size_t count = fillPacket(packet, valid, o, unitDirs, first, tMin, tMaxM);
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        rtcOccluded16(valid, rtcScene_.get(), &context, &packet);
        for (std::size_t k = 0; k < count; ++k) occluded += packet.tfar[k] < 0.0f ? 1 : 0;  // -inf when occluded
    }
    return occluded;
}

void EmbreeScene::intersectSides(const glm::dvec3& origin, std::span<const glm::dvec3> unitDirs, double tMaxM,
                                 RayEnds start, std::span<HitSide> out) const {
    if (out.size() != unitDirs.size())
        throw std::invalid_argument("EmbreeScene::intersectSides: " + std::to_string(out.size()) + " results for " +
                                    std::to_string(unitDirs.size()) + " rays");
    std::fill(out.begin(), out.end(), HitSide{});
    const double tMin = start == RayEnds::Lifted ? 0.0 : rayEpsilonAtM(origin);
    if (!(tMaxM > tMin)) return;
    constexpr std::size_t kPacket = 16;
    const glm::vec3 o(origin - origin_);
    for (std::size_t first = 0; first < unitDirs.size(); first += kPacket) {
        alignas(64) RTCRayHit16 packet;
        alignas(64) int valid[kPacket];
        const std::size_t count = fillPacket(packet.ray, valid, o, unitDirs, first, tMin, tMaxM);
        std::fill(std::begin(packet.hit.geomID), std::end(packet.hit.geomID), RTC_INVALID_GEOMETRY_ID);
        std::fill(std::begin(packet.hit.instID[0]), std::end(packet.hit.instID[0]), RTC_INVALID_GEOMETRY_ID);
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        rtcIntersect16(valid, rtcScene_.get(), &context, &packet);
        for (std::size_t k = 0; k < count; ++k) {
            if (packet.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;
            HitSide& side = out[first + k];
            side.hit = true;
            side.instance = packet.hit.geomID[k];
            side.distanceM = double(packet.ray.tfar[k]);
            side.frontFacing = glm::dot(faceNormal(side.instance, packet.hit.primID[k]), unitDirs[first + k]) < 0.0;
        }
    }
}

FaceHit EmbreeScene::intersectFace(const glm::dvec3& origin, const glm::dvec3& unitDir, double tNearM) const {
    return nearestFace(origin, unitDir, tNearM, std::numeric_limits<double>::infinity());
}

FaceHit EmbreeScene::nearestFace(const glm::dvec3& origin, const glm::dvec3& unitDir, double tNearM, double tFarM) const {
    RTCRayHit rayHit{};
    rayHit.ray = makeRay(origin, unitDir, tNearM, tFarM);
    rayHit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rayHit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rtcIntersect1(rtcScene_.get(), &context, &rayHit);
    if (rayHit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
    return {true, rayHit.hit.geomID, rayHit.hit.primID, rayHit.hit.u, rayHit.hit.v, double(rayHit.ray.tfar)};
}

std::optional<Hit> EmbreeScene::intersect(const glm::dvec3& origin, const glm::dvec3& dir, double tMaxM, RayEnds start) const {
    const double tMin = start == RayEnds::Lifted ? 0.0 : rayEpsilonAtM(origin);
    if (!(tMaxM > tMin)) return std::nullopt;
    const glm::dvec3 unitDir = unitDirection(dir);
    const FaceHit nearest = nearestFace(origin, unitDir, tMin, tMaxM);
    if (!nearest.hit) return std::nullopt;

    Hit hit;
    hit.instance = nearest.instance;
    hit.face = nearest.face;
    hit.distanceM = nearest.distanceM;
    hit.barycentrics = {double(nearest.u), double(nearest.v)};
    const SurfaceMesh& mesh = scene_->instances[hit.instance].mesh;
    const auto& v = triangle(hit.instance, hit.face);
    const double w0 = 1.0 - hit.barycentrics.x - hit.barycentrics.y;
    hit.position = w0 * toGlm(mesh.point(mesh.vertex_handle(v[0]))) +
                   hit.barycentrics.x * toGlm(mesh.point(mesh.vertex_handle(v[1]))) +
                   hit.barycentrics.y * toGlm(mesh.point(mesh.vertex_handle(v[2])));
    hit.geometricNormal = faceNormal(hit.instance, hit.face);
    hit.frontFacing = glm::dot(hit.geometricNormal, unitDir) < 0.0;
    return hit;
}

const std::array<std::uint32_t, 3>& EmbreeScene::triangle(std::uint32_t instance, std::uint32_t face) const {
    return triangles_.at(instance).vertices.at(face);
}

const glm::dvec3& EmbreeScene::faceNormal(std::uint32_t instance, std::uint32_t face) const {
    return triangles_.at(instance).normals.at(face);
}

}  // namespace hemibake
