#include "baker/direct/emissive_area_lights.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

#include "baker/rays/embree_scene.h"
#include "mesh/cell_key.h"
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

// Van der Corput's radical inverse in base 2: i's bits mirrored about the binary point.
double radicalInverse2(std::uint32_t i) {
    i = (i << 16) | (i >> 16);
    i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
    i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
    i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
    i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
    return double(i) * 0x1p-32;
}

// Receiver–emitter distances, in units of the sum of their bounding radii, past which an emitter triangle's form
// factor is taken as one value over the receiver: the mean of the receiver's edge midpoints beyond
// kPerPointDistance (for an element, a point source instead while the error budget below allows), a point source
// beyond kPointSourceDistance. Errors measured against per-point contours:
// tests/baker/direct/emissive_area_lights_test.cpp (FarEmittersAreOneValuePerElement).
constexpr double kPerPointDistance = 4.0;
constexpr double kPointSourceDistance = 24.0;
// A cluster of emitter triangles (not closer than kPerPointDistance), or a single triangle between the two distances
// above, is one point source while the sum of the receiver's error bounds, luminance(F·L)·(kClusterErrorScale·
// (extent/d)² + normal spread·extent/d), stays under kClusterErrorBudget of its unoccluded total. Measured against
// per-point contours: FarClustersOfLampsAreOnePointSourceAndKeepTheirShadows (the scale is empirical: 400 far lamps
// and no near one came out at 6.9e-4 worst point under the 1e-3 budget).
constexpr double kClusterErrorScale = 4.0;
constexpr double kClusterErrorBudget = 1e-3;
// Emitters wholly beyond kFarFreePaths median free paths of the emitters' light (farDistanceM()) are the far group:
// on a level, lamps of other rooms, mostly hidden. Their light is estimated by its own shadow rays, unbiased
// (Σ f/pdf), so their cut only shapes where those rays go: clusters are taken whole at any distance (straddling
// the receiver's plane or theirs, with an upper bound of what they can give as their weight) and split only while
// their error bounds exceed kFarClusterErrorBudget of the group's total. Cutting them to the near group's 10⁻³ made
// an element's cut grow with the level (50 → 240 entries for 10 copies of a level; session 30).
constexpr double kFarFreePaths = 4.0;
constexpr double kFarClusterErrorBudget = 0.25;
// And at most this many far entries: clusters straddling a plane carry their whole weight as error, so on large
// levels the budget alone kept splitting them (22.8 entries an element on one copy of a tiled level, 72.9 on ten,
// the element's view 5.4 → 17.7 µs; bench_hemicube's LevelEmitterViews). Any cut is unbiased here; the cap bounds
// the cost per receiver, whatever the level's size.
constexpr std::size_t kMaxFarClusters = 32;
// Rays from the emitters that set the free path (deterministic: the same level gives the same far distance).
constexpr int kFreePathRays = 1024;
// Marks a traversal entry as wholly beyond the far distance (node indices stay below 2³¹).
constexpr std::uint32_t kFarBit = 0x80000000u;
// The far group's shadow rays per point: the near group's count over this (at least one).
constexpr int kFarRayDivisor = 4;

// The sphere about a triangle's centroid that holds it (the distances above are measured between these).
struct BoundingSphere {
    glm::dvec3 centre;
    double radiusM;
};
BoundingSphere boundingSphere(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 centre = (a + b + c) / 3.0;
    return {centre, std::max({glm::length(a - centre), glm::length(b - centre), glm::length(c - centre)})};
}

// A uniform point on triangle (a, b, c) from r1, r2 in [0, 1).
glm::dvec3 pointOnTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double r1, double r2) {
    const double sq = std::sqrt(r1);
    return (1.0 - sq) * a + sq * (1.0 - r2) * b + sq * r2 * c;
}

// The entry of a running sum `cdf` (offset by `offset`) that `target` falls in, and its [below, above).
struct Stratum {
    std::size_t k;
    double below, above;
};
Stratum stratumAt(const std::vector<double>& cdf, double offset, double target) {
    const std::size_t k = std::min<std::size_t>(
        std::size_t(std::upper_bound(cdf.begin(), cdf.end(), target - offset) - cdf.begin()), cdf.size() - 1);
    return {k, offset + (k ? cdf[k - 1] : 0.0), offset + cdf[k]};
}

// The triangle of [first, first + count) whose share of the running power sum `prefix` holds `within`.
std::uint32_t triangleAtPower(const std::vector<double>& prefix, std::uint32_t first, std::uint32_t count, double within) {
    const double* p = prefix.data();
    return std::min<std::uint32_t>(std::uint32_t(std::upper_bound(p + first + 1, p + first + count + 1, within) - p) - 1,
                                   first + count - 1);
}

// One value over the receiver for node `node` (F·L per channel, `weight` its luminance): summed, and in the CDF.
void addConstant(EmissiveAreaLights::ReceiverView& view, std::uint32_t node, const glm::dvec3& fl, double weight, bool far) {
    std::vector<std::uint32_t>& nodes = far ? view.farConstant : view.constant;
    std::vector<double>& cdf = far ? view.farConstantCdf : view.constantCdf;
    if (!far) view.constantUnoccluded += fl;  // the far group's light is its rays' (irradianceOverPiAt)
    nodes.push_back(node);
    cdf.push_back((cdf.empty() ? 0.0 : cdf.back()) + weight);
}

}  // namespace

EmissiveAreaLights::EmissiveAreaLights(const PatchMesh& mesh, const EmbreeScene& rays, int samplesPerPoint)
    : rays_(rays), samples_(samplesPerPoint) {
    if (samplesPerPoint < 1) throw std::invalid_argument("EmissiveAreaLights: samplesPerPoint must be at least 1");
    const ElementArrays& el = mesh.elements;
    auto triangleOf = [](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& radiance) {
        Triangle t;
        t.a = a;
        t.b = b;
        t.c = c;
        const glm::dvec3 cross = glm::cross(b - a, c - a);
        const double twiceArea = glm::length(cross);
        t.normal = twiceArea > 0.0 ? cross / twiceArea : glm::dvec3(0.0);
        t.areaM2 = 0.5 * twiceArea;
        t.radiance = radiance;
        const BoundingSphere sphere = boundingSphere(a, b, c);
        t.centroid = sphere.centre;
        t.radiusM = sphere.radiusM;
        return t;
    };
    // The cost per receiver grows with the triangles (a test each, a contour for the near ones), so the elements
    // bisected from one input triangle are merged back into it: an emitting face cut into 1,000 elements is still
    // one light. A group is merged only when
    // its elements tile a triangle exactly (their areas sum to the area of the triangle spanned by their extreme
    // vertices, and they share one plane and one radiance); faces cut along solids or trimmed to their exposed
    // area stay as their elements.
    std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint8_t>, std::vector<std::uint32_t>> groups;
    for (std::uint32_t e = 0; e < el.size(); ++e) {
        const glm::vec3 l = el.emittedRadiance[e];
        if (l.x > 0.0f || l.y > 0.0f || l.z > 0.0f) groups[{el.instance[e], el.sourceFace[e], el.backSide[e]}].push_back(e);
    }
    inputTriangles_ = groups.size();
    for (const auto& [key, members] : groups) {
        const glm::dvec3 radiance(el.emittedRadiance[members[0]]);
        double area = 0.0;
        bool uniform = true;
        for (std::uint32_t e : members) {
            area += el.areaM2[e];
            uniform &= el.emittedRadiance[e] == el.emittedRadiance[members[0]];
        }
        if (members.size() > 1 && uniform) {
            // The triangle of the group's extreme vertices: the farthest pair, then the vertex farthest from their line.
            const glm::dvec3 first = el.vertices[el.triangles[members[0]][0]];
            glm::dvec3 a = first, b = first, c = first;
            for (std::uint32_t e : members)
                for (std::uint32_t v : el.triangles[e])
                    if (glm::length(el.vertices[v] - first) > glm::length(a - first)) a = el.vertices[v];
            for (std::uint32_t e : members)
                for (std::uint32_t v : el.triangles[e])
                    if (glm::length(el.vertices[v] - a) > glm::length(b - a)) b = el.vertices[v];
            double best = 0.0;
            for (std::uint32_t e : members)
                for (std::uint32_t v : el.triangles[e]) {
                    const double twice = glm::length(glm::cross(b - a, el.vertices[v] - a));
                    if (twice > best) {
                        best = twice;
                        c = el.vertices[v];
                    }
                }
            Triangle whole = triangleOf(a, b, c, radiance);
            const glm::dvec3 n(el.normal[members[0]]);
            if (glm::dot(whole.normal, n) < 0.0) whole = triangleOf(a, c, b, radiance);
            if (whole.areaM2 > 0.0 && std::abs(whole.areaM2 - area) <= 1e-9 * whole.areaM2 && glm::dot(whole.normal, n) > 0.999) {
                triangles_.push_back(whole);
                continue;
            }
        }
        for (std::uint32_t e : members) {
            const Triangle t = triangleOf(el.vertices[el.triangles[e][0]], el.vertices[el.triangles[e][1]],
                                          el.vertices[el.triangles[e][2]], glm::dvec3(el.emittedRadiance[e]));
            if (t.areaM2 > 0.0) triangles_.push_back(t);  // a degenerate element emits nothing
        }
    }
    // One hierarchy per dominant normal direction, so that lamps facing one way cluster (a level's ceiling lamps
    // all face down; mixed with the walls' they would form cones too wide to aggregate).
    std::stable_sort(triangles_.begin(), triangles_.end(),
                     [](const Triangle& x, const Triangle& y) { return cubeFaceOf(x.normal) < cubeFaceOf(y.normal); });
    if (triangles_.size() >= kFarBit / 2) throw std::length_error("EmissiveAreaLights: too many emitter triangles");
    nodes_.reserve(2 * triangles_.size());
    for (std::size_t first = 0; first < triangles_.size();) {
        std::size_t last = first + 1;
        while (last < triangles_.size() && cubeFaceOf(triangles_[last].normal) == cubeFaceOf(triangles_[first].normal)) ++last;
        roots_.push_back(buildNodes(std::uint32_t(first), std::uint32_t(last)));
        first = last;
    }
    powerPrefix_.assign(triangles_.size() + 1, 0.0);  // in the order the hierarchy left them
    for (std::size_t i = 0; i < triangles_.size(); ++i)
        powerPrefix_[i + 1] = powerPrefix_[i] + triangles_[i].areaM2 * luminance(triangles_[i].radiance);
    const double freePathM = medianFreePathM();
    farDistanceM_ = freePathM > 0.0 ? kFarFreePaths * freePathM : std::numeric_limits<double>::infinity();
}

double EmissiveAreaLights::medianFreePathM() const {
    if (triangles_.empty() || !(powerPrefix_.back() > 0.0)) return std::numeric_limits<double>::infinity();
    std::vector<double> lengthsM(kFreePathRays);
    for (int i = 0; i < kFreePathRays; ++i) {
        // Triangles by power, points uniform on them, cosine-distributed directions: where the light goes first.
        const double target = (i + 0.5) / kFreePathRays * powerPrefix_.back();
        const Triangle& t = triangles_[triangleAtPower(powerPrefix_, 0, std::uint32_t(triangles_.size()), target)];
        const double r1 = std::fmod(0.5 + i * 0.6180339887498949, 1.0), r2 = radicalInverse2(std::uint32_t(i));
        const glm::dvec3 x = pointOnTriangle(t.a, t.b, t.c, r1, r2);
        const glm::dvec3 d = cosineDirection(t.normal, std::fmod(r2 + 0.5, 1.0), std::fmod(0.25 + i * 0.7548776662466927, 1.0));
        const auto hit = rays_.intersect(rays_.offsetFromSurface(x, t.normal), d, std::numeric_limits<double>::infinity(),
                                         EmbreeScene::RayEnds::Lifted);
        lengthsM[i] = hit ? hit->distanceM : std::numeric_limits<double>::infinity();
    }
    std::nth_element(lengthsM.begin(), lengthsM.begin() + kFreePathRays / 2, lengthsM.end());
    return lengthsM[kFreePathRays / 2];
}

std::uint32_t EmissiveAreaLights::buildNodes(std::uint32_t first, std::uint32_t last) {
    Node node;
    node.first = first;
    node.count = last - first;
    double weight = 0.0;
    glm::dvec3 weighted(0.0), areaNormal(0.0), lo(std::numeric_limits<double>::infinity()), hi(-lo);
    node.boxLo = lo;
    node.boxHi = hi;
    for (std::uint32_t i = first; i < last; ++i) {
        const Triangle& t = triangles_[i];
        const double w = t.areaM2 * luminance(t.radiance);
        weight += w;
        weighted += w * t.centroid;
        areaNormal += t.areaM2 * t.normal;
        for (int c = 0; c < 3; ++c) node.powerNormal[c] += t.areaM2 * t.radiance[c] * t.normal;
        lo = glm::min(lo, t.centroid);
        hi = glm::max(hi, t.centroid);
        node.boxLo = glm::min(node.boxLo, glm::min(t.a, glm::min(t.b, t.c)));
        node.boxHi = glm::max(node.boxHi, glm::max(t.a, glm::max(t.b, t.c)));
    }
    node.centre = weight > 0.0 ? weighted / weight : 0.5 * (lo + hi);
    const double axisLength = glm::length(areaNormal);
    node.axis = axisLength > 0.0 ? areaNormal / axisLength : glm::dvec3(0.0, 0.0, 1.0);
    for (std::uint32_t i = first; i < last; ++i) {
        const Triangle& t = triangles_[i];
        node.radiusM = std::max(node.radiusM, glm::length(t.centroid - node.centre) + t.radiusM);
        node.normalChord = std::max(node.normalChord, glm::length(t.normal - node.axis));
    }
    if (node.count == 1) {  // a leaf is its triangle, as the per-triangle tests measure it
        node.centre = triangles_[first].centroid;
        node.radiusM = triangles_[first].radiusM;
    }
    const auto index = std::uint32_t(nodes_.size());
    nodes_.push_back(node);
    if (node.count > 1) {
        // Median split along the centroids' longest extent.
        const int axis = largestComponent(hi - lo);
        const std::uint32_t middle = first + node.count / 2;
        std::nth_element(triangles_.begin() + first, triangles_.begin() + middle, triangles_.begin() + last,
                         [axis](const Triangle& x, const Triangle& y) { return x.centroid[axis] < y.centroid[axis]; });
        const std::uint32_t left = buildNodes(first, middle);
        const std::uint32_t right = buildNodes(middle, last);
        nodes_[index].left = left;
        nodes_[index].right = right;
    }
    return index;
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

double EmissiveAreaLights::viewTriangle(std::uint32_t node, const glm::dvec3 (&receiver)[3], const glm::dvec3& centroid,
                                        double radiusM, const glm::dvec3& n, bool refined, bool far, ReceiverView& view) const {
    const std::uint32_t i = nodes_[node].first;
    const Triangle& t = triangles_[i];
    const glm::dvec3 v[3] = {t.a, t.b, t.c};
    // Which side of each other's plane the two lie on. Wholly behind either: nothing at any point (as the
    // per-point test and clipping find).
    int inFront = 0, behind = 0;
    for (const glm::dvec3& r : receiver) {
        const double s = glm::dot(r - t.a, t.normal);
        inFront += s > 0.0;
        behind += !(s > 0.0);
    }
    if (inFront == 0) return 0.0;
    int above = 0, below = 0;
    for (const glm::dvec3& x : v) {
        const double s = glm::dot(x - centroid, n);
        above += s > 0.0;
        below += s < 0.0;
    }
    if (above == 0) return 0.0;
    const double distanceM = glm::length(t.centroid - centroid);
    const double extentM = radiusM + t.radiusM;
    if (distanceM < kPerPointDistance * extentM) {
        view.perPoint.push_back(i);
        return unoccludedFormFactor(centroid, n, v, 3) * luminance(t.radiance);  // an estimate, for the error budget
    }
    // Farther, the unoccluded term is smooth over the receiver even where one straddles the other's plane (on a
    // level, a wall's plane runs through the lamps of the room, a lamp's side faces' planes through the floor;
    // evaluating those per point made 11 of a 100k-level element's 17 per-point triangles). The receiver's plane is
    // every point's, so the emitter is clipped by it once; a receiver straddling the emitter's plane averages its
    // front part (the back part sees nothing), three edge midpoints per triangle of it.
    glm::dvec3 emitter[4];
    int corners = 3;
    if (below > 0) {
        corners = clipAbove(centroid, n, v, 3, emitter);
        if (corners < 3) return 0.0;
    } else {
        std::copy(v, v + 3, emitter);
    }
    auto meanOverTriangle = [&](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
        return (unoccludedFormFactor(0.5 * (a + b), n, emitter, corners) + unoccludedFormFactor(0.5 * (b + c), n, emitter, corners) +
                unoccludedFormFactor(0.5 * (c + a), n, emitter, corners)) / 3.0;
    };
    double f;
    if (behind > 0) {
        // The receiver's points behind the emitter get nothing from it, those in front their share of the front
        // part's mean (irradianceOverPiAt tests each point): spread over every point, a point behind would have had a share
        // that none of its shadow rays can reach (they all leave behind the emitter), and the estimator would have
        // taken it as unshadowed — light in a sealed room next to a lit one.
        glm::dvec3 front[4];
        const int k = clipAbove(t.a, t.normal, receiver, 3, front);
        const double wholeM2 = 0.5 * glm::length(glm::cross(receiver[1] - receiver[0], receiver[2] - receiver[0]));
        if (k < 3 || !(wholeM2 > 0.0)) return 0.0;
        // F(p) = h(p)·∫ cosθ_r / (π r³) dA with h(p) p's height over the emitter's plane, the integral smooth: a
        // point in front takes G·h(p), G from the front part's mean (h is linear, its mean is h at the centroid).
        // Continuous at the plane, as F is: a constant there would be a step the element's points resolve to 1/k.
        double sum = 0.0, frontM2 = 0.0;
        glm::dvec3 weighted(0.0);
        for (int j = 1; j + 1 < k; ++j) {
            const double areaM2 = 0.5 * glm::length(glm::cross(front[j] - front[0], front[j + 1] - front[0]));
            sum += areaM2 * meanOverTriangle(front[0], front[j], front[j + 1]);
            frontM2 += areaM2;
            weighted += areaM2 * (front[0] + front[j] + front[j + 1]) / 3.0;
        }
        if (!(sum > 0.0) || !(frontM2 > 0.0)) return 0.0;
        const double meanHeightM = glm::dot(weighted / frontM2 - t.a, t.normal);
        if (!(meanHeightM > 0.0)) return 0.0;
        view.frontOnly.push_back({i, sum / frontM2 / meanHeightM});
        return sum / wholeM2 * luminance(t.radiance);
    } else if (below == 0 && !refined && (radiusM > 0.0 || distanceM >= kPointSourceDistance * extentM)) {
        // A point source at the centroid: F = A·cosθ_r·cosθ_t / (π d²), relative error O((extent/d)²). Beyond
        // kPointSourceDistance always; nearer, a receiving element takes it as a candidate under the error budget
        // (viewFrom), to be refined to the midpoint rule (refined = true) if it weighs too much.
        const glm::dvec3 d = (t.centroid - centroid) / distanceM;
        f = t.areaM2 * glm::dot(n, d) * -glm::dot(t.normal, d) / (M_PI * distanceM * distanceM);
        if (distanceM < kPointSourceDistance * extentM) {
            if (!(f > 0.0)) return 0.0;
            const double weight = f * luminance(t.radiance), ratio = extentM / distanceM;
            (far ? view.farClusters : view.clusters).push_back({weight * kClusterErrorScale * ratio * ratio, weight, f * t.radiance, node});
            return weight;
        }
    } else if (!(radiusM > 0.0)) {
        f = unoccludedFormFactor(centroid, n, emitter, corners);  // a point receiver (a texel)
    } else {
        f = meanOverTriangle(receiver[0], receiver[1], receiver[2]);
    }
    if (!(f > 0.0)) return 0.0;
    addConstant(view, node, f * t.radiance, f * luminance(t.radiance), far);
    return f * luminance(t.radiance);
}

void EmissiveAreaLights::viewFrom(const glm::dvec3 (&receiver)[3], const glm::dvec3& n, ReceiverView& view) const {
    view.perPoint.clear();
    view.frontOnly.clear();
    view.constant.clear();
    view.constantCdf.clear();
    view.constantUnoccluded = glm::dvec3(0.0);
    view.farConstant.clear();
    view.farConstantCdf.clear();
    view.clusters.clear();
    view.farClusters.clear();
    const auto [centroid, radiusM] = boundingSphere(receiver[0], receiver[1], receiver[2]);
    // Lightcuts-like: clusters are taken whole while the sum of their error bounds stays within the budget of the
    // unoccluded total (luminance); the one with the largest bound is split first. Per group: [0] near, [1] far.
    double total[2] = {0.0, 0.0}, errorSum[2] = {0.0, 0.0};
    auto byError = [](const ReceiverView::Cluster& x, const ReceiverView::Cluster& y) { return x.errorBound < y.errorBound; };
    auto visit = [&](std::uint32_t entry) {
        const std::uint32_t index = entry & ~kFarBit;
        const Node& node = nodes_[index];
        const glm::dvec3 toNode = node.centre - centroid;
        const double distanceM = glm::length(toNode);
        const bool far = (entry & kFarBit) || distanceM - node.radiusM - radiusM >= farDistanceM_;
        std::vector<ReceiverView::Cluster>& heap = far ? view.farClusters : view.clusters;
        if (node.count == 1) {
            const std::size_t candidates = heap.size();
            total[far] += viewTriangle(index, receiver, centroid, radiusM, n, false, far, view);
            if (heap.size() > candidates) {  // a point source for now
                errorSum[far] += heap.back().errorBound;
                std::push_heap(heap.begin(), heap.end(), byError);
            }
            return;
        }
        auto open = [&] {
            view.stack.push_back(node.right | (far ? kFarBit : 0u));
            view.stack.push_back(node.left | (far ? kFarBit : 0u));
        };
        auto take = [&](const glm::dvec3& fl, double weight, double errorBound) {
            heap.push_back({errorBound, weight, fl, index});
            std::push_heap(heap.begin(), heap.end(), byError);
            total[far] += weight;
            errorSum[far] += errorBound;
        };
        const double extentM = radiusM + node.radiusM;
        if (!far && distanceM < kPerPointDistance * extentM) return open();
        // The cluster against the receiver's plane (its box's extreme heights): wholly below, nothing; straddling,
        // its parts.
        const glm::dvec3 boxMid = 0.5 * (node.boxLo + node.boxHi), boxHalf = 0.5 * (node.boxHi - node.boxLo);
        auto heightsAlong = [&](const glm::dvec3& v) {  // min and max of v·(x − centroid) over the box
            const double mid = glm::dot(v, boxMid - centroid), half = glm::dot(glm::abs(v), boxHalf);
            return std::pair<double, double>{mid - half, mid + half};
        };
        const auto [lowest, highest] = heightsAlong(n);
        if (highest <= 0.0) return;
        // The receiver against the cluster's planes: n_t·(r − x) = axis·(r − x) + (n_t − axis)·(r − x) for every
        // triangle t, point x on it and receiver point r (n_t within normalChord of the axis, |r − x| ≤ distance +
        // extent).
        const auto [nearest, farthest] = heightsAlong(node.axis);
        const double slack = radiusM + node.normalChord * (distanceM + extentM);
        if (-nearest + slack <= 0.0) return;  // behind every triangle
        const bool straddles = lowest < 0.0 || -farthest - slack <= 0.0;
        if (straddles && !far) return open();
        if (straddles) {
            // A far cluster across either plane: weighted by the most it can give (cosθ_r ≤ highest / d_min, cosθ_t ≤
            // the receiver's greatest height over its planes / d_min), so that its triangles in front keep their rays.
            const double nearestM = distanceM - extentM;
            const double power = powerPrefix_[node.first + node.count] - powerPrefix_[node.first];
            const double weight = power * std::min(1.0, highest / nearestM) * std::min(1.0, (-nearest + slack) / nearestM) /
                                  (M_PI * nearestM * nearestM);
            if (weight > 0.0) take(glm::dvec3(0.0), weight, weight);
            return;
        }
        // A point source at the power-weighted centroid: F·L per channel = cosθ_r / (π d²) · Σ A_t·L_t·cosθ_t. Its
        // error is second order in extent / d (the first-order terms cancel about that centroid while the cosines
        // θ_t agree), plus first order in the normals' spread.
        const glm::dvec3 d = toNode / distanceM;
        const double scale = glm::dot(n, d) / (M_PI * distanceM * distanceM);
        const glm::dvec3 fl(-scale * glm::dot(node.powerNormal[0], d), -scale * glm::dot(node.powerNormal[1], d),
                            -scale * glm::dot(node.powerNormal[2], d));
        const double weight = luminance(fl);
        if (!(weight > 0.0)) return;
        const double ratio = extentM / distanceM;
        take(fl, weight, weight * (kClusterErrorScale * ratio * ratio + node.normalChord * ratio));
    };
    auto drain = [&] {
        while (!view.stack.empty()) {
            const std::uint32_t entry = view.stack.back();
            view.stack.pop_back();
            visit(entry);
        }
    };
    view.stack.assign(roots_.rbegin(), roots_.rend());
    drain();
    const double budget[2] = {kClusterErrorBudget, kFarClusterErrorBudget};
    for (;;) {
        const int group = !view.clusters.empty() && errorSum[0] > budget[0] * total[0]           ? 0
                          : !view.farClusters.empty() && errorSum[1] > budget[1] * total[1] &&
                                    view.farClusters.size() < kMaxFarClusters
                              ? 1
                              : -1;
        if (group < 0) break;
        std::vector<ReceiverView::Cluster>& heap = group ? view.farClusters : view.clusters;
        std::pop_heap(heap.begin(), heap.end(), byError);
        const ReceiverView::Cluster split = heap.back();
        heap.pop_back();
        total[group] -= split.weight;
        errorSum[group] -= split.errorBound;
        if (nodes_[split.node].count == 1) {  // a triangle taken as a point source: the midpoint rule instead
            total[group] += viewTriangle(split.node, receiver, centroid, radiusM, n, true, group == 1, view);
            continue;
        }
        const std::uint32_t flag = group ? kFarBit : 0u;
        view.stack.push_back(nodes_[split.node].right | flag);
        view.stack.push_back(nodes_[split.node].left | flag);
        drain();
    }
    for (const ReceiverView::Cluster& c : view.clusters) addConstant(view, c.node, c.fl, c.weight, false);
    for (const ReceiverView::Cluster& c : view.farClusters) addConstant(view, c.node, c.fl, c.weight, true);
}

glm::dvec3 EmissiveAreaLights::irradianceOverPiAt(const glm::dvec3& p, const glm::dvec3& n, std::uint64_t seed) const {
    if (triangles_.empty()) return glm::dvec3(0.0);
    thread_local ReceiverView view;
    const glm::dvec3 point[3] = {p, p, p};
    viewFrom(point, n, view);
    return irradianceOverPiAt(p, n, seed, view);
}

glm::dvec3 EmissiveAreaLights::irradianceOverPiAt(const glm::dvec3& p, const glm::dvec3& n, std::uint64_t seed,
                                                  const ReceiverView& view) const {
    if (triangles_.empty()) return glm::dvec3(0.0);
    // Unoccluded contribution of each triangle facing p; the sampling distribution follows its luminance. The
    // CDF runs over the per-point triangles first, then over the receiver's constant ones.
    thread_local std::vector<double> cdf;
    thread_local std::vector<std::uint32_t> index;
    cdf.clear();
    index.clear();
    glm::dvec3 unoccluded = view.constantUnoccluded;
    double total = 0.0;
    for (std::uint32_t i : view.perPoint) {
        const Triangle& t = triangles_[i];
        if (!(glm::dot(p - t.a, t.normal) > 0.0)) continue;  // p is behind the emitting side
        const glm::dvec3 v[3] = {t.a, t.b, t.c};
        const double f = unoccludedFormFactor(p, n, v, 3);
        if (!(f > 0.0)) continue;
        unoccluded += f * t.radiance;
        total += f * luminance(t.radiance);
        cdf.push_back(total);
        index.push_back(i);
    }
    for (const ReceiverView::FrontOnly& front : view.frontOnly) {
        const Triangle& t = triangles_[front.triangle];
        const double heightM = glm::dot(p - t.a, t.normal);
        if (!(heightM > 0.0)) continue;
        const double f = front.formFactorPerM * heightM;
        unoccluded += f * t.radiance;
        total += f * luminance(t.radiance);
        cdf.push_back(total);
        index.push_back(front.triangle);
    }
    const double perPointTotal = total;
    if (!view.constantCdf.empty()) total += view.constantCdf.back();
    const double farTotal = view.farConstantCdf.empty() ? 0.0 : view.farConstantCdf.back();
    if (!(total > 0.0) && !(farTotal > 0.0)) return glm::dvec3(0.0);

    // The stratum's triangle: its index and its [below, above) share of the CDF. A cluster's share is divided among
    // its triangles by their power A·lum(L) (their cosines agree), so the pdf is the cluster's times the triangle's.
    struct Pick {
        std::uint32_t triangle;
        double below, above;
    };
    auto pickIn = [&](const std::vector<std::uint32_t>& nodes, const std::vector<double>& c, double offset, double target) {
        const auto [k, below, above] = stratumAt(c, offset, target);
        const Node& node = nodes_[nodes[k]];
        if (node.count == 1) return Pick{node.first, below, above};
        const double* prefix = powerPrefix_.data();
        const double base = prefix[node.first], power = prefix[node.first + node.count] - base;
        const double within = base + std::clamp((target - below) / std::max(above - below, 1e-300), 0.0, 1.0) * power;
        const std::uint32_t t = triangleAtPower(powerPrefix_, node.first, node.count, within);
        const double share = (above - below) / power;
        return Pick{t, below + (prefix[t] - base) * share, below + (prefix[t + 1] - base) * share};
    };
    // The near CDF runs over the per-point triangles first, then over the receiver's constant clusters.
    auto pickNear = [&](double target) {
        if (!cdf.empty() && (target < perPointTotal || view.constantCdf.empty())) {
            const auto [k, below, above] = stratumAt(cdf, 0.0, target);
            return Pick{index[k], below, above};
        }
        return pickIn(view.constant, view.constantCdf, perPointTotal, target);
    };

    const glm::dvec3 origin = rays_.offsetFromSurface(p, n);
    std::uint64_t state = splitMix64(seed);
    const double rotation = unitDouble(state = splitMix64(state));
    // Shadow ray s of `count`, stratified over a CDF of `groupTotal`: f/pdf of its point (without the 1/π; zero where
    // the triangle is clipped away) and whether it is visible.
    struct Sample {
        glm::dvec3 fOverPdf{0.0};
        bool visible = false;
    };
    auto sample = [&](int s, int count, double groupTotal, const auto& pick) -> Sample {
        const double u = (s + unitDouble(state = splitMix64(state))) / count;  // stratified over the CDF
        const Pick chosen = pick(u * groupTotal);
        const Triangle& t = triangles_[chosen.triangle];
        const double pdf = (chosen.above - chosen.below) / groupTotal;
        // Points spread over the triangle, not only over the triangles: the stratum's place within the triangle's
        // share of the CDF (stratified) and a rotated radical inverse (Hammersley-like), so a lamp that is one
        // triangle keeps its penumbrae as smooth as the same lamp split into many elements.
        const double r1 = std::clamp((u * groupTotal - chosen.below) / std::max(chosen.above - chosen.below, 1e-300), 0.0,
                                     std::nextafter(1.0, 0.0));
        const double r2 = std::fmod(radicalInverse2(std::uint32_t(s)) + rotation, 1.0);
        const glm::dvec3 x = pointOnTriangle(t.a, t.b, t.c, r1, r2);
        const glm::dvec3 d = x - p;
        const double dist2 = glm::dot(d, d);
        if (!(dist2 > 0.0) || !(pdf > 0.0)) return {};
        const double cosP = glm::dot(n, d), cosX = -glm::dot(t.normal, d);
        if (cosP <= 0.0 || cosX <= 0.0) return {};  // the clipped-away part of the triangle
        return {t.radiance * (t.areaM2 * cosP * cosX / (dist2 * dist2 * pdf)),
                !rays_.occluded(origin, rays_.offsetFromSurface(x, t.normal), EmbreeScene::RayEnds::Lifted)};
    };
    glm::dvec3 result(0.0);
    if (total > 0.0) {
        // Near: the exact unoccluded term times the visible share of its shadow rays (ratio estimator).
        glm::dvec3 weighted(0.0), visible(0.0);
        for (int s = 0; s < samples_; ++s) {
            const Sample one = sample(s, samples_, total, pickNear);
            weighted += one.fOverPdf;
            if (one.visible) visible += one.fOverPdf;
        }
        for (int c = 0; c < 3; ++c)
            result[c] = weighted[c] > 0.0 ? unoccluded[c] * (visible[c] / weighted[c]) : unoccluded[c];
    }
    if (farTotal > 0.0) {
        // Far: Σ f/pdf over its own rays (unbiased whatever the cut, which only decides where they go).
        const int farSamples = std::max(1, samples_ / kFarRayDivisor);
        glm::dvec3 visible(0.0);
        auto pickFar = [&](double target) { return pickIn(view.farConstant, view.farConstantCdf, 0.0, target); };
        for (int s = 0; s < farSamples; ++s) {
            const Sample one = sample(s, farSamples, farTotal, pickFar);
            if (one.visible) visible += one.fOverPdf;
        }
        result += visible / (M_PI * farSamples);
    }
    return result;
}

std::unique_ptr<EmissiveAreaLights> makeEmissiveAreaLights(const PatchMesh& mesh, const EmbreeScene& rays,
                                                           const LightingSettings& lighting, int samplesPerPoint) {
    if (lighting.emitters != EmitterLighting::Rays) return nullptr;
    auto lights = std::make_unique<EmissiveAreaLights>(mesh, rays, samplesPerPoint > 0 ? samplesPerPoint : lighting.emitterSamples);
    if (lights->empty()) return nullptr;
    return lights;
}

std::size_t emitterTrianglesNearOneReceiver(const Scene& scene, double elementSizeM) {
    const double cellM = kPerPointDistance * elementSizeM;
    const bool oneBlock = !(cellM > 0.0) || !std::isfinite(cellM);
    // Cells are counted in 2⁵² steps at most, so a cell size far below the scene's extent (1 µm elements 100 km out)
    // stays an exact integer.
    static constexpr double kMostCells = 4503599627370496.0;
    auto cellOf = [cellM](double x) { return std::int64_t(std::clamp(std::floor(x / cellM), -kMostCells, kMostCells)); };
    std::unordered_map<std::uint64_t, std::size_t> perCell;
    std::vector<glm::i64vec3> cells;  // of every emitting face, so each occupied cell's block is summed
    std::size_t total = 0;
    for (const MeshInstance& instance : scene.instances) {
        const Material& material = scene.materials[std::size_t(instance.material)];
        if (!material.isEmissive()) continue;
        const std::size_t sides = material.doubleSided ? 2u : 1u;
        for (const auto& face : instance.mesh.faces()) {
            total += sides;
            if (oneBlock) continue;
            glm::dvec3 centroid(0.0);
            int corners = 0;
            for (const auto& vertex : face.vertices()) {
                centroid += toGlm(instance.mesh.point(vertex));
                ++corners;
            }
            centroid /= double(std::max(corners, 1));
            const glm::i64vec3 cell(cellOf(centroid.x), cellOf(centroid.y), cellOf(centroid.z));
            perCell[cellKey(cell.x, cell.y, cell.z)] += sides;
            cells.push_back(cell);
        }
    }
    if (oneBlock) return total;
    std::size_t most = 0;
    for (const glm::i64vec3& cell : cells) {
        std::size_t block = 0;
        for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
                for (std::int64_t dz = -1; dz <= 1; ++dz) {
                    const auto found = perCell.find(cellKey(cell.x + dx, cell.y + dy, cell.z + dz));
                    if (found != perCell.end()) block += found->second;
                }
        most = std::max(most, block);
    }
    return most;
}

}  // namespace hemibake
