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
#include <tbb/parallel_sort.h>

#include "baker/rays/embree_scene.h"
#include "mesh/frame_math.h"
#include "mesh/surface_mesh.h"

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

// The bounds of the elements' vertices (the ray offset and the float origin of both ways to trace).
Bounds elementBounds(const ElementArrays& el) {
    Bounds bounds;
    for (const glm::dvec3& v : el.vertices) bounds.extend(v);
    return bounds;
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
        const Bounds bounds = elementBounds(el);
        origin = bounds.empty() ? glm::dvec3(0.0) : bounds.centre();
        diagonal = bounds.empty() ? 0.0 : bounds.diagonal();
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

namespace {

// The elements grouped into islands by instance (mesh/islands.h), floats taken from the elements' centre as the BVH
// takes them.
SceneIslands elementIslands(const ElementArrays& el) {
    const Bounds all = elementBounds(el);
    return SceneIslands::ofElements(el, all.empty() ? glm::dvec3(0.0) : all.centre());
}

// The ray offset of each island. One island keeps the elements' whole diagonal, as before islands (their vertex bounds,
// unused vertices included, which an island's triangles may not reach).
std::vector<double> rayOffsets(const SceneIslands& islands, double elementDiagonalM) {
    if (islands.size() <= 1) return {std::max(EmbreeScene::kRayEpsilonRelative * elementDiagonalM, 1e-9)};
    std::vector<double> offsets(islands.size());
    for (std::size_t k = 0; k < islands.size(); ++k)
        offsets[k] = std::max(islands.lengthM(k, EmbreeScene::kRayEpsilonRelative, EmbreeScene::kRayEpsilonFloatSteps), 1e-9);
    return offsets;
}

double largest(const std::vector<double>& values) { return *std::max_element(values.begin(), values.end()); }

}  // namespace

ElementRayScene::ElementRayScene(const PatchMesh& mesh)
    : mesh_(mesh), embree_(std::make_unique<Embree>(mesh)), islands_(elementIslands(mesh.elements)),
      islandOffsetM_(rayOffsets(islands_, embree_->diagonal)), rayOffsetM_(largest(islandOffsetM_)),
      twins_(std::size_t(std::count(embree_->hasTwin.begin(), embree_->hasTwin.end(), 1))) {}

// Each face of the input holds the elements subdivided from it, per side (0: the face's own winding, 1: the back copy
// of a double-sided face), as affine maps from the face's barycentrics (Embree's u, v) to each element's, binned in a
// grid over the face's (u, v) square where a face has many.
struct ElementRayScene::Faces {
    struct Locator {
        float u0, v0, m00, m01, m10, m11;  // (b1, b2) = M·((u, v) − (u0, v0))
        float heightM;                     // the element's least height: how far outside a barycentric deficit lies
        std::uint32_t element;
    };
    // One side's elements: `count` locators from `first` scanned in turn, or (grid > 0) a grid × grid grid of cells
    // from cell `first`; count 0 and grid 0: none (a hole).
    struct Side {
        std::uint32_t first = 0, count = 0, grid = 0;
    };
    // What a hit on a face needs, in one place: its normal (which side the ray arrives on) and its two sides.
    struct Record {
        glm::vec3 normal{0.0f};
        Side side[2];
    };
    // Elements per grid cell over a face's (u, v) square, of which the face is half: about twice this many per cell
    // the face covers. A side with at most kScanned elements is scanned without a grid.
    static constexpr double kElementsPerCell = 1.0;
    static constexpr double kMostCellsPerAxis = 256.0;
    static constexpr std::uint32_t kScanned = 4;

    const EmbreeScene& input;
    std::vector<std::uint32_t> firstRecord;  // per instance: its faces' records start here
    std::vector<Record> records;
    std::vector<std::uint32_t> cellStart;  // CSR over every grid's cells: cellItems[cellStart[c], cellStart[c + 1])
    std::vector<std::uint32_t> cellItems;  // into locators
    std::vector<Locator> locators;
    double holeM = 0.0;  // a point farther outside every element than this is a hole in the face

    Faces(const PatchMesh& mesh, const EmbreeScene& in, double holeToleranceM) : input(in), holeM(holeToleranceM) {
        const Scene& scene = in.scene();
        const ElementArrays& el = mesh.elements;
        // The input face of every element: by (instance, source face), as the subdivision copied it.
        std::vector<std::vector<std::int32_t>> faceOfSource(scene.instances.size());
        for (std::size_t i = 0; i < scene.instances.size(); ++i) {
            const SurfaceMesh& m = scene.instances[i].mesh;
            firstRecord.push_back(std::uint32_t(records.size()));
            for (std::uint32_t f = 0; f < m.n_faces(); ++f) records.push_back({glm::vec3(in.faceNormal(std::uint32_t(i), f)), {}});
            for (auto f : m.faces()) {
                const int source = m.sourceFace(f);
                if (source < 0) continue;
                if (std::size_t(source) >= faceOfSource[i].size()) faceOfSource[i].resize(std::size_t(source) + 1, -1);
                if (faceOfSource[i][std::size_t(source)] < 0) faceOfSource[i][std::size_t(source)] = f.idx();
            }
        }
        // Elements sorted by (instance, face, side), largest first within each: the likeliest hit is tried first.
        struct Entry {
            std::uint64_t key;
            std::uint32_t element;
        };
        std::vector<Entry> entries;
        entries.reserve(el.size());
        for (std::uint32_t e = 0; e < el.size(); ++e) {
            const std::uint32_t i = el.instance[e];
            if (i >= faceOfSource.size() || el.sourceFace[e] >= faceOfSource[i].size()) continue;
            const std::int32_t f = faceOfSource[i][el.sourceFace[e]];
            if (f < 0) continue;
            entries.push_back({(std::uint64_t(i) << 33) | (std::uint64_t(f) << 1) | el.backSide[e], e});
        }
        tbb::parallel_sort(entries.begin(), entries.end(), [&](const Entry& a, const Entry& b) {
            return a.key != b.key ? a.key < b.key : el.areaM2[a.element] != el.areaM2[b.element] ? el.areaM2[a.element] > el.areaM2[b.element] : a.element < b.element;
        });
        cellStart.push_back(0);
        for (std::size_t begin = 0; begin < entries.size();) {
            std::size_t end = begin;
            while (end < entries.size() && entries[end].key >> 1 == entries[begin].key >> 1) ++end;
            const auto instance = std::uint32_t(entries[begin].key >> 33);
            const auto face = std::uint32_t((entries[begin].key >> 1) & 0xFFFFFFFFull);
            Record& record = records[firstRecord[instance] + face];
            const SurfaceMesh& m = scene.instances[instance].mesh;
            const std::array<std::uint32_t, 3>& corner = in.triangle(instance, face);
            auto point = [&](std::uint32_t v) { return toGlm(m.point(SurfaceMesh::VertexHandle(int(v)))); };
            const glm::dvec3 p0 = point(corner[0]), e1 = point(corner[1]) - p0, e2 = point(corner[2]) - p0;
            const glm::dvec3 n = glm::cross(e1, e2);
            const double n2 = glm::dot(n, n);
            for (std::size_t first = begin; first < end;) {
                std::size_t last = first;
                while (last < end && entries[last].key == entries[first].key) ++last;
                if (n2 > 0.0) record.side[entries[first].key & 1] = addSide(el, entries, first, last, p0, e1, e2, n, n2);
                first = last;
            }
            begin = end;
        }
    }

    template <class Entries>
    Side addSide(const ElementArrays& el, const Entries& entries, std::size_t first, std::size_t last, const glm::dvec3& p0, const glm::dvec3& e1, const glm::dvec3& e2, const glm::dvec3& n, double n2) {
        auto inFace = [&](std::uint32_t v) {  // the face's barycentrics (u, v) of vertex v, as Embree reports a hit
            const glm::dvec3 d = el.vertices[v] - p0;
            return glm::dvec2(glm::dot(glm::cross(d, e2), n) / n2, glm::dot(glm::cross(e1, d), n) / n2);
        };
        const auto firstLocator = std::uint32_t(locators.size());
        std::vector<std::array<glm::dvec2, 2>> box;  // per locator of this side, in (u, v), grown by a margin
        for (std::size_t k = first; k < last; ++k) {
            const std::uint32_t e = entries[k].element;
            const std::array<std::uint32_t, 3>& t = el.triangles[e];
            const glm::dvec2 c0 = inFace(t[0]), c1 = inFace(t[1]), c2 = inFace(t[2]);
            const glm::dvec2 a = c1 - c0, b = c2 - c0;
            const double det = a.x * b.y - a.y * b.x;
            if (!(det != 0.0) || !(el.areaM2[e] > 0.0)) continue;  // no area: never the element a ray meets
            double longest = 0.0;
            for (int c = 0; c < 3; ++c)
                longest = std::max(longest, glm::length(el.vertices[t[std::size_t(c)]] - el.vertices[t[std::size_t((c + 1) % 3)]]));
            locators.push_back({float(c0.x), float(c0.y), float(b.y / det), float(-b.x / det), float(-a.y / det),
                                float(a.x / det), float(2.0 * el.areaM2[e] / longest), e});
            const double margin = 1e-4;
            box.push_back({glm::min(c0, glm::min(c1, c2)) - margin, glm::max(c0, glm::max(c1, c2)) + margin});
        }
        const auto count = std::uint32_t(locators.size() - firstLocator);
        if (count <= kScanned) return {firstLocator, count, 0};
        const auto grid = std::uint32_t(std::clamp(std::ceil(std::sqrt(double(count) / kElementsPerCell)), 1.0, kMostCellsPerAxis));
        const Side s{std::uint32_t(cellStart.size() - 1), 0, grid};
        auto cellRange = [&](double lo, double hi) {
            return std::pair<std::uint32_t, std::uint32_t>(
                std::uint32_t(std::clamp(std::floor(lo * grid), 0.0, double(grid - 1))),
                std::uint32_t(std::clamp(std::floor(hi * grid), 0.0, double(grid - 1))));
        };
        std::vector<std::uint32_t> perCell(std::size_t(grid) * grid, 0);
        for (const auto& [lo, hi] : box) {
            const auto [x0, x1] = cellRange(lo.x, hi.x);
            const auto [y0, y1] = cellRange(lo.y, hi.y);
            for (std::uint32_t y = y0; y <= y1; ++y)
                for (std::uint32_t x = x0; x <= x1; ++x) ++perCell[std::size_t(y) * grid + x];
        }
        const auto base = std::uint32_t(cellItems.size());
        std::vector<std::uint32_t> cursor(perCell.size());
        for (std::size_t c = 0, sum = base; c < perCell.size(); ++c) {
            cursor[c] = std::uint32_t(sum);
            sum += perCell[c];
            cellStart.push_back(std::uint32_t(sum));
        }
        cellItems.resize(cellStart.back());
        for (std::uint32_t k = 0; k < count; ++k) {
            const auto& [lo, hi] = box[k];
            const auto [x0, x1] = cellRange(lo.x, hi.x);
            const auto [y0, y1] = cellRange(lo.y, hi.y);
            for (std::uint32_t y = y0; y <= y1; ++y)
                for (std::uint32_t x = x0; x <= x1; ++x) cellItems[cursor[std::size_t(y) * grid + x]++] = firstLocator + k;
        }
        return s;
    }

    // The element of `side` holding the point at face barycentrics (u, v) and its own (b1, b2); a point just outside
    // every element (an edge, by float rounding) goes to the one it is least outside of, clamped in. False: a hole.
    bool locate(const Side& side, float u, float v, std::uint32_t& element, double& b1, double& b2) const {
        const Locator* best = nullptr;
        float bestOutsideM = std::numeric_limits<float>::infinity(), bestB1 = 0.0f, bestB2 = 0.0f;
        auto test = [&](const Locator& l) {
            const float du = u - l.u0, dv = v - l.v0;
            const float p = l.m00 * du + l.m01 * dv, q = l.m10 * du + l.m11 * dv;
            const float inside = std::min({p, q, 1.0f - p - q});
            if (inside >= 0.0f) {
                element = l.element;
                b1 = p;
                b2 = q;
                return true;
            }
            const float outsideM = -inside * l.heightM;
            if (outsideM < bestOutsideM) {
                bestOutsideM = outsideM;
                best = &l;
                bestB1 = p;
                bestB2 = q;
            }
            return false;
        };
        if (side.grid == 0) {
            for (std::uint32_t k = side.first; k < side.first + side.count; ++k)
                if (test(locators[k])) return true;
        } else {
            const std::uint32_t g = side.grid;
            const auto x = std::uint32_t(std::clamp(u * float(g), 0.0f, float(g - 1))),
                       y = std::uint32_t(std::clamp(v * float(g), 0.0f, float(g - 1)));
            const std::uint32_t cell = side.first + y * g + x;
            for (std::uint32_t k = cellStart[cell]; k < cellStart[cell + 1]; ++k)
                if (test(locators[cellItems[k]])) return true;
        }
        if (!best || !(double(bestOutsideM) <= holeM)) return false;
        element = best->element;
        const double p = std::clamp(double(bestB1), 0.0, 1.0), q = std::clamp(double(bestB2), 0.0, 1.0);
        const double over = std::max(p + q - 1.0, 0.0);
        b1 = p - 0.5 * over;
        b2 = q - 0.5 * over;
        return true;
    }
};

namespace {

double elementDiagonalM(const PatchMesh& mesh) {
    const Bounds bounds = elementBounds(mesh.elements);
    return bounds.empty() ? 0.0 : bounds.diagonal();
}

}  // namespace

ElementRayScene::ElementRayScene(const PatchMesh& mesh, const EmbreeScene& input)
    : mesh_(mesh), islands_(elementIslands(mesh.elements)), islandOffsetM_(rayOffsets(islands_, elementDiagonalM(mesh))),
      rayOffsetM_(largest(islandOffsetM_)) {
    const std::vector<std::uint8_t> twins = elementsWithTwins(mesh.elements);
    twins_ = std::size_t(std::count(twins.begin(), twins.end(), 1));
    faces_ = std::make_unique<Faces>(mesh, input, rayOffsetM_);
}

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
    if (faces_) return traceFaces(SharedOrigin{origin}, dirs, hits);
    tracePackets(SharedOrigin{origin}, dirs, hits);
}

void ElementRayScene::trace(std::span<const glm::dvec3> origins, std::span<const glm::dvec3> dirs,
                            std::span<ElementHit> hits) const {
    if (origins.size() != dirs.size())
        throw std::invalid_argument("ElementRayScene::trace: origins and directions differ in count");
    if (faces_) return traceFaces(OriginPerRay{origins}, dirs, hits);
    tracePackets(OriginPerRay{origins}, dirs, hits);
}

template <class OriginOf>
void ElementRayScene::traceFaces(const OriginOf& originOf, std::span<const glm::dvec3> dirs, std::span<ElementHit> hits) const {
    if (hits.size() != dirs.size()) throw std::invalid_argument("ElementRayScene::trace: hits and directions differ in count");
    const Faces& faces = *faces_;
    thread_local std::vector<FaceHit> found;
    found.resize(dirs.size());
    faces.input.intersectFaces(originOf, dirs, std::span<FaceHit>(found.data(), dirs.size()));
    // A hole goes on past its face; a handful of holes in a row along one ray is more than any level has.
    constexpr int kMostHoles = 16;
    for (std::size_t k = 0; k < dirs.size(); ++k) {
        ElementHit& hit = hits[k];
        hit = ElementHit{};
        FaceHit face = found[k];
        for (int holes = 0; face.hit && holes <= kMostHoles; ++holes) {
            // The side the ray arrives on: the back copy of a double-sided face if it has one, else the face's own
            // elements, seen from behind (a Back hit, as the elements' BVH reports one without a twin).
            const Faces::Record& record = faces.records[faces.firstRecord[face.instance] + face.face];
            const glm::vec3& n = record.normal;
            const bool fromFront = n.x * float(dirs[k].x) + n.y * float(dirs[k].y) + n.z * float(dirs[k].z) < 0.0f;
            const bool back = !fromFront && (record.side[1].count > 0 || record.side[1].grid > 0);
            if (faces.locate(record.side[back ? 1 : 0], face.u, face.v, hit.element, hit.b1, hit.b2)) {
                hit.distanceM = face.distanceM;
                hit.kind = fromFront || back ? ElementHit::Kind::Front : ElementHit::Kind::Back;
                break;
            }
            face = faces.input.intersectFace(originOf(k), dirs[k], face.distanceM + faces.holeM);
        }
    }
}

template <class OriginOf>
void ElementRayScene::tracePackets(const OriginOf& originOf, std::span<const glm::dvec3> dirs, std::span<ElementHit> hits) const {
    if (hits.size() != dirs.size()) throw std::invalid_argument("ElementRayScene::trace: hits and directions differ in count");
    const std::vector<glm::vec3>& normals = mesh_.elements.normal;
    for (std::size_t first = 0; first < dirs.size(); first += 16) {
        alignas(64) RTCRayHit16 packet;
        alignas(64) int valid[16];
        const std::size_t count = fillHitPacket(packet, valid, originOf, embree_->origin, dirs, first);
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
