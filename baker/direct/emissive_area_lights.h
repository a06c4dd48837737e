#pragma once
// Emissive surfaces as area lights: the direct light they give a surface point, by Lambert's exact contour
// formula times a shadow-ray estimate of how much of them is visible. The alternative (shooting emitters'
// power through item-buffer hemicubes) aliases a small bright source into every receiver's value and puts
// its shadows on the element grid; here the direct term is exact wherever an emitter is wholly visible or
// wholly hidden, and penumbrae are as sharp as the receiver's sampling (a texel, not an element).
//
// Estimator at point p with normal n: E_u = Σ_t L_t·F(p → t) over emitter triangles t (each clipped to the
// hemisphere above p), then E = E_u · Σ_i a_i·V_i / Σ_i a_i over shadow rays to points x_i picked on triangle t_i
// with probability ∝ L_t·F(p → t) (stratified), a_i = L_t·A_t·cosθ_p·cosθ_x / (r²·pdf(t_i)): the visible
// fraction weighted like the integrand. Exact when all V_i agree; a ratio estimator (consistent) otherwise.
// Emitters wholly beyond farDistanceM() of the receiver (a level's other rooms) are a group of their own, estimated
// by Σ f/pdf over rays of their own (a quarter as many): unbiased however coarsely they are clustered, so their
// cut stays small where the ratio estimator's E_u would need every far cluster resolved to 10⁻³ of the total.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <memory>

#include "baker/direct/lighting_settings.h"
#include "mesh/patches.h"
#include "mesh/scene.h"

namespace hemibake {

class EmbreeScene;

class EmissiveAreaLights {
public:
    // Every emitting element of `mesh` (its own side only: emission leaves the front). `rays` must outlive this.
    EmissiveAreaLights(const PatchMesh& mesh, const EmbreeScene& rays, int samplesPerPoint);

    bool empty() const { return triangles_.empty(); }
    std::size_t triangleCount() const { return triangles_.size(); }
    // Input triangles the lights come from (per side of a double-sided face), as emitterTrianglesNearOneReceiver
    // counts them: faces cut along solids or trimmed stay as several triangles each, so triangleCount() may be larger.
    std::size_t inputTriangleCount() const { return inputTriangles_; }
    double emittedPowerW() const;  // π·L_e·A summed over channels and triangles

    // The emitters as one planar receiving element (or point) sees them. A contour integral per emitter triangle per
    // point made the direct light of a 100k-triangle level cost 1,144 s (64 points × ~1,600 triangles per element);
    // most triangles are far from most elements, where the unoccluded term is smooth over the element. Triangles
    // close to it are evaluated per point; the others once per element (mean of the three edge midpoints, exact for
    // a quadratic field; clipped to the receiver's plane, or over the receiver's part in front of theirs, where one
    // straddles the other's plane) or, farther still, as point sources. Far enough, a whole cluster of emitters
    // facing one way is one point source (a hierarchy over the triangles), so a receiver's cost grows with the
    // emitters near it, not with the level's: testing every triangle per receiver made the 300k-triangle level's
    // direct light 4.3× the 100k level's for 3× the elements.
    struct ReceiverView {
        std::vector<std::uint32_t> perPoint;    // triangles evaluated at every point
        // Triangles whose plane runs through the receiver: F = formFactorPerM × p's height over their plane in
        // front of it, nothing behind.
        struct FrontOnly {
            std::uint32_t triangle;
            double formFactorPerM;
        };
        std::vector<FrontOnly> frontOnly;
        std::vector<std::uint32_t> constant;    // clusters (nodes) whose form factor is one value over the receiver
        std::vector<double> constantCdf;        // running Σ F̄_node·luminance over `constant`
        glm::dvec3 constantUnoccluded{0.0};     // Σ F̄_t·L_t over the triangles of `constant`
        // The far group: clusters wholly beyond farDistanceM() of the receiver, cut to the coarser
        // kFarClusterErrorBudget of their own total. Their weights only say where the group's rays go.
        std::vector<std::uint32_t> farConstant;
        std::vector<double> farConstantCdf;     // running Σ weight over `farConstant`
        // Traversal scratch: nodes to visit, and the clusters taken whole so far (a max-heap on errorBound).
        struct Cluster {
            double errorBound, weight;  // luminance of the error bound and of fl
            glm::dvec3 fl;              // F·L per channel
            std::uint32_t node;
        };
        std::vector<std::uint32_t> stack;       // node | kFarBit when it is wholly beyond farDistanceM()
        std::vector<Cluster> clusters, farClusters;
    };
    // Fills `view` (reused: no allocation once warm) for the triangle `receiver` (three equal points: a point) with
    // unit normal n. Thread-safe for distinct views.
    void viewFrom(const glm::dvec3 (&receiver)[3], const glm::dvec3& n, ReceiverView& view) const;

    // Distance from a receiver beyond which emitters are the far group: kFarFreePaths × the median free path of
    // rays leaving the emitters (the size of the rooms they light); infinite (no far group) when most rays escape.
    double farDistanceM() const { return farDistanceM_; }

    // E/π (W·m⁻²·sr⁻¹) at p, unit normal n (the receiving side). `seed` decorrelates neighbouring points.
    glm::dvec3 irradianceOverPiAt(const glm::dvec3& p, const glm::dvec3& n, std::uint64_t seed) const;
    // The same at a point p of the receiver `view` was made for (p's normal is the receiver's).
    glm::dvec3 irradianceOverPiAt(const glm::dvec3& p, const glm::dvec3& n, std::uint64_t seed, const ReceiverView& view) const;

    // Unoccluded E/π from one planar polygon of constant radiance L_e: Lambert's formula on the part of the
    // polygon above p's tangent plane (it must lie in front of p's surface to contribute).
    static double unoccludedFormFactor(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3* polygon, int count);

private:
    struct Triangle {
        glm::dvec3 a, b, c;
        glm::dvec3 normal;  // unit, the emitting side
        double areaM2;
        glm::dvec3 radiance;  // L_e
        glm::dvec3 centroid;
        double radiusM;       // of the sphere about the centroid that holds it
    };
    // A cluster of triangles_[first, first + count): a leaf is one triangle. Far away, a cluster whose normals agree
    // is a point source at its power-weighted centroid with intensity Σ A_t·L_t·(n_t·ω) per channel.
    struct Node {
        glm::dvec3 centre{0.0};      // Σ A·lum(L)·centroid / Σ A·lum(L) (a leaf: its triangle's centroid)
        double radiusM = 0.0;        // of the sphere about `centre` that holds every triangle
        glm::dvec3 boxLo{0.0}, boxHi{0.0};  // of its vertices: planes through a flat row of lamps miss it
        glm::dvec3 axis{0.0};        // unit mean normal (area-weighted)
        double normalChord = 0.0;    // max |n_t − axis| over the triangles (chord of the normal cone)
        // Σ A_t·L_t,c·n_t per channel c (W·sr⁻¹ per unit cosine, over π).
        glm::dvec3 powerNormal[3] = {glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0)};
        std::uint32_t first = 0, count = 0;
        std::uint32_t left = 0, right = 0;  // children when count > 1
    };
    std::uint32_t buildNodes(std::uint32_t first, std::uint32_t last);
    // A triangle alone (a leaf): per point, one value over the receiver, or nothing. Appends to `view`; returns its
    // luminance(F·L) (per point: at the receiver's centroid, an estimate). A receiving element may get a triangle
    // nearer than kPointSourceDistance as a point-source candidate (appended to view.clusters, not yet a heap
    // entry); `refined` asks for the midpoint rule instead. `far`: its one value or candidacy goes to the far group.
    double viewTriangle(std::uint32_t node, const glm::dvec3 (&receiver)[3], const glm::dvec3& centroid, double radiusM,
                        const glm::dvec3& n, bool refined, bool far, ReceiverView& view) const;
    // Median distance that rays leaving the emitters (by power, cosine-distributed) travel to a surface; infinite
    // when most escape. Deterministic.
    double medianFreePathM() const;

    std::vector<Triangle> triangles_;
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> roots_;    // one hierarchy per dominant normal axis and sign
    std::vector<double> powerPrefix_;     // Σ A·lum(L) over triangles_[0, i): picks a triangle within a cluster
    std::size_t inputTriangles_ = 0;
    double farDistanceM_ = 0.0;
    const EmbreeScene& rays_;
    int samples_;
};

// The area lights a bake uses, or null when emitters shoot through hemicubes instead: by setting, or because the
// scene has no emitter. Whether a scene has too many emitters near one receiver for rays is the solve's decision
// (solveScene, by emitterTrianglesNearOneReceiver; SolveReport::emittersByRays), made once before subdividing so that
// emitter patches are sized for it; later stages follow the report. `samplesPerPoint` 0 = LightingSettings::emitterSamples.
std::unique_ptr<EmissiveAreaLights> makeEmissiveAreaLights(const PatchMesh& mesh, const EmbreeScene& rays,
                                                           const LightingSettings& lighting, int samplesPerPoint = 0);

// The most emitter input triangles (per emitting side of a double-sided face, as inputTriangleCount() counts them)
// whose centroids lie in one 3 × 3 × 3 block of cubic cells of side kPerPointDistance × elementSizeM: at least as
// many as lie within that distance of a receiver in the block's middle cell, where each costs a contour per point
// (farther ones are clustered). What LightingSettings::maxRayTracedEmitters limits: a level's other rooms' lamps do
// not count; a densely tessellated emitting surface beside receivers does. A scene-wide count sent a 300k-triangle
// level's lamps (30 copies of a level, 192 lamp triangles each, 5,760 in all) through the shooter, where one copy's
// went by rays; near one receiver it counts 192. elementSizeM ≤ 0 or not finite counts the whole scene as one block. Thread-safe; throws only std::bad_alloc.
std::size_t emitterTrianglesNearOneReceiver(const Scene& scene, double elementSizeM);

}  // namespace hemibake
