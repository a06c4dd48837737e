#pragma once
// Ray queries against a Scene's original triangles through Embree 3: geomID = instance index, primID = face
// index in that instance's SurfaceMesh.
//
// Precision: vertices are stored in float *relative to the centre of the scene bounds*, so a level 1e5 m from
// the world origin keeps the precision of one built at the origin (a float at 1e5 m has a 7.8 mm step). Queries
// take world-space doubles and are converted into that frame.
//
// Ray epsilon: Embree intersects in float, so a ray leaving a surface can re-hit it at a distance of a few float
// ulps of the coordinates around it, i.e. proportional to their distance from the frame's centre, not to the
// surface's size. rayEpsilonAtM(p) is that bound with a wide margin (kRayEpsilonRelative × the diagonal, ≈ 60 ulps at
// half of it). Two ways to use it, chosen per query by RayEnds:
//  - OnSurface (default): the ray's ends may lie on surfaces; the epsilon is skipped along the ray at each end.
//    Simple, but any surface closer than the epsilon to an end is missed (light leaks into concave corners and
//    through walls thinner than that), and at a grazing angle θ the skipped piece is only epsilon·sinθ away
//    from the surface, where float error wins (measured in a furnace: 2e-4 to 4e-4 too dark 1 to 0.1 mm from a wall).
//  - Lifted: the caller moved the ends off their surfaces with offsetFromSurface() (along the normal, to the side
//    the ray travels), which no float error can undo at any angle; nothing is skipped, so nearby surfaces count.
//    DirectLight and PathTracer use this for all their rays.
// The epsilon is 4e-6 × the diagonal: 16 µm for a 2 × 2 × 3 m room, 0.7 mm for a 100 m cube of a level. The diagonal
// is the island's the ray starts in (mesh/islands.h), not the scene's: copies of a room a kilometre apart keep the
// room's epsilon, raised to 4 float steps at the island's distance from the scene's centre (0.7 mm at 1.5 km). A
// scene of one island, which any level whose parts touch is, has the scene diagonal's epsilon everywhere.
//
// Thread safety: every const query may run concurrently (Embree's rtcIntersect1/rtcOccluded1/rtcOccluded16 are).
#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include "mesh/islands.h"
#include "mesh/scene.h"

namespace hemibake {

// Embree's error code as words, for exception messages.
const char* embreeErrorName(RTCError error);

struct Hit {
    std::uint32_t instance = 0;   // Scene::instances index
    std::uint32_t face = 0;       // face index in the instance's SurfaceMesh
    double distanceM = 0.0;       // along the (normalised) ray direction
    glm::dvec2 barycentrics{0.0};  // weights of triangle(instance, face)[1] and [2]
    glm::dvec3 position{0.0};     // world space, recomputed in double from the barycentrics: on the triangle's plane
    glm::dvec3 geometricNormal{0.0};  // world space, unit, counter-clockwise front (computed in double)
    bool frontFacing = false;     // the ray arrived on the side geometricNormal points to
};

// What a ray meets first, without the point it meets: enough to tell open space, a surface's front or its back.
struct HitSide {
    bool hit = false;
    std::uint32_t instance = 0;  // Scene::instances index (when hit)
    double distanceM = 0.0;      // along the unit direction (when hit)
    bool frontFacing = false;    // as Hit::frontFacing
};

// The input face a ray meets: which, where on it (Embree's barycentrics u, v of its corners 1 and 2, in the order of
// triangle()), and how far along the unit direction.
struct FaceHit {
    bool hit = false;
    std::uint32_t instance = 0, face = 0;
    float u = 0.0f, v = 0.0f;
    double distanceM = 0.0;
};

// Ray k of a packet of 16: origin (float, relative to the scene's origin), unit direction, [tnear, tfar], all masks.
inline void setPacketRay(RTCRay16& packet, std::size_t k, const glm::vec3& origin, const glm::dvec3& unitDir, float tnear,
                         float tfar) {
    packet.org_x[k] = origin.x;
    packet.org_y[k] = origin.y;
    packet.org_z[k] = origin.z;
    packet.dir_x[k] = float(unitDir.x);
    packet.dir_y[k] = float(unitDir.y);
    packet.dir_z[k] = float(unitDir.z);
    packet.tnear[k] = tnear;
    packet.tfar[k] = tfar;
    packet.time[k] = 0.0f;
    packet.mask[k] = std::numeric_limits<unsigned>::max();
    packet.id[k] = unsigned(k);
    packet.flags[k] = 0;
}

// Fills a packet of 16 for intersection with rays first.. of `unitDirs` (at most 16; lanes past the end repeat the
// last ray, masked off in `valid`) from originOf(ray) (world space, made relative to `sceneOrigin` in float),
// [0, ∞), no hit yet. Returns how many lanes are live.
template <class OriginOf>
std::size_t fillHitPacket(RTCRayHit16& packet, int (&valid)[16], const OriginOf& originOf, const glm::dvec3& sceneOrigin,
                          std::span<const glm::dvec3> unitDirs, std::size_t first) {
    const std::size_t count = std::min<std::size_t>(16, unitDirs.size() - first);
    for (std::size_t k = 0; k < 16; ++k) {
        valid[k] = k < count ? -1 : 0;
        const std::size_t ray = first + std::min(k, count - 1);
        setPacketRay(packet.ray, k, glm::vec3(originOf(ray) - sceneOrigin), unitDirs[ray], 0.0f,
                     std::numeric_limits<float>::infinity());
        packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    return count;
}

class EmbreeScene {
public:
    // `scene` must outlive this object (hits are completed from its double-precision vertices).
    explicit EmbreeScene(const Scene& scene);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;
    EmbreeScene(EmbreeScene&&) noexcept;
    EmbreeScene& operator=(EmbreeScene&&) noexcept;

    enum class RayEnds { OnSurface, Lifted };  // see the header comment

    // Is anything strictly between the two points? OnSurface: segments shorter than 2 × rayEpsilonM() never are.
    bool occluded(const glm::dvec3& from, const glm::dvec3& to, RayEnds ends = RayEnds::OnSurface) const;
    // Is anything along the ray closer than tMaxM? `dir` is normalised here, so distances are metres whatever its
    // length; a zero or non-finite `dir` throws std::invalid_argument.
    bool occludedRay(const glm::dvec3& origin, const glm::dvec3& dir, double tMaxM, RayEnds start = RayEnds::OnSurface) const;
    // How many of the rays from `origin` along unit directions `unitDirs` something occludes closer than tMaxM, traced
    // in packets of 16 (rays from one point share most of their traversal): occludedRay for each, faster.
    std::size_t countOccluded(const glm::dvec3& origin, std::span<const glm::dvec3> unitDirs, double tMaxM,
                              RayEnds start = RayEnds::OnSurface) const;
    // The nearest hit of each ray from `origin` along unit directions `unitDirs` closer than tMaxM, into `out` (as
    // many), traced in packets of 16: what intersect() finds, less the point and face (the side against the face's
    // double-precision normal, as there). Throws std::invalid_argument if the sizes differ.
    void intersectSides(const glm::dvec3& origin, std::span<const glm::dvec3> unitDirs, double tMaxM, RayEnds start,
                        std::span<HitSide> out) const;
    // The nearest face each ray meets, from origins[k] (lifted: nothing is skipped near them) along unit directions
    // dirs[k] (both relative to nothing: world space), traced in packets of 16; `originOf(k)` gives origin k, so one
    // shared origin needs no copies. Thread-safe.
    template <class OriginOf>
    void intersectFaces(const OriginOf& originOf, std::span<const glm::dvec3> unitDirs, std::span<FaceHit> out) const;
    // The nearest face along one ray beyond tNearM (world space, unit direction). Thread-safe.
    FaceHit intersectFace(const glm::dvec3& origin, const glm::dvec3& unitDir, double tNearM) const;

    // Nearest hit closer than tMaxM along the ray, `dir` as for occludedRay.
    std::optional<Hit> intersect(const glm::dvec3& origin, const glm::dvec3& dir, double tMaxM,
                                 RayEnds start = RayEnds::OnSurface) const;

    // Vertex indices (OpenMesh idx) of a face, in the order the barycentrics refer to.
    const std::array<std::uint32_t, 3>& triangle(std::uint32_t instance, std::uint32_t face) const;
    // Unit geometric normal of a face (zero for a degenerate face).
    const glm::dvec3& faceNormal(std::uint32_t instance, std::uint32_t face) const;

    // A ray end lifted off surface point p to the side `unitNormal` points to (for RayEnds::Lifted).
    glm::dvec3 offsetFromSurface(const glm::dvec3& p, const glm::dvec3& unitNormal) const {
        return p + rayEpsilonAtM(p) * unitNormal;
    }

    // The ray epsilon at p: its island's (see the header comment). Thread-safe.
    double rayEpsilonAtM(const glm::dvec3& p) const {
        return islandEpsilonM_.size() == 1 ? islandEpsilonM_[0] : islandEpsilonM_[islands_.islandAt(p)];
    }
    // The largest ray epsilon of any island: the scene's, when it is one island.
    double rayEpsilonM() const { return rayEpsilonM_; }
    const SceneIslands& islands() const { return islands_; }
    const glm::dvec3& origin() const { return origin_; }
    const Scene& scene() const { return *scene_; }

    // See the header comment: ≈ 60 float ulps of a coordinate at half the island's diagonal.
    static constexpr double kRayEpsilonRelative = 4e-6;
    // The least epsilon, in float steps (floatStepM) at the island's farthest coordinate from the scene's centre:
    // binds only for islands small against their distance from it (≤ 67 keeps a one-island scene's epsilon exactly
    // relative). Two turned furnaces 3 km apart (RayGatherer test) re-hit their own walls at 0.1 step, not at 0.5;
    // 4 leaves a margin of 8. More costs light in gaps: 16 steps at 1.5 km (2.9 mm) made one copy of a level 5 % darker
    // on the mean of its surfaces (docs/performance.md, session 43).
    static constexpr double kRayEpsilonFloatSteps = 4.0;

private:
    struct DeviceDeleter { void operator()(RTCDeviceTy* device) const; };
    struct SceneDeleter { void operator()(RTCSceneTy* scene) const; };
    struct InstanceTriangles {
        std::vector<std::array<std::uint32_t, 3>> vertices;
        std::vector<glm::dvec3> normals;
    };

    void checkDevice(const char* what) const;
    RTCRay makeRay(const glm::dvec3& origin, const glm::dvec3& unitDir, double tNearM, double tFarM) const;
    // The nearest face along one ray in [tNearM, tFarM] (intersect and intersectFace).
    FaceHit nearestFace(const glm::dvec3& origin, const glm::dvec3& unitDir, double tNearM, double tFarM) const;

    const Scene* scene_ = nullptr;
    std::unique_ptr<RTCDeviceTy, DeviceDeleter> device_;
    std::unique_ptr<RTCSceneTy, SceneDeleter> rtcScene_;
    std::vector<InstanceTriangles> triangles_;
    glm::dvec3 origin_{0.0};
    SceneIslands islands_;
    std::vector<double> islandEpsilonM_;  // per island (at least one entry)
    double rayEpsilonM_ = 0.0;            // the largest of them
};

template <class OriginOf>
void EmbreeScene::intersectFaces(const OriginOf& originOf, std::span<const glm::dvec3> unitDirs, std::span<FaceHit> out) const {
    for (std::size_t first = 0; first < unitDirs.size(); first += 16) {
        alignas(64) RTCRayHit16 packet;
        alignas(64) int valid[16];
        const std::size_t count = fillHitPacket(packet, valid, originOf, origin_, unitDirs, first);
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        rtcIntersect16(valid, rtcScene_.get(), &context, &packet);
        for (std::size_t k = 0; k < count; ++k) {
            FaceHit& hit = out[first + k];
            hit = FaceHit{};
            if (packet.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;
            hit = {true, packet.hit.geomID[k], packet.hit.primID[k], packet.hit.u[k], packet.hit.v[k], double(packet.ray.tfar[k])};
        }
    }
}

}  // namespace hemibake
