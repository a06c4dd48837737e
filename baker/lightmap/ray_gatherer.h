#pragma once
// The final gather by rays: E/π at a point is the mean radiance its cosine-distributed rays meet on the solved
// elements (plus the texel light inside them, and the sky where they escape): the same integral a radiance
// hemicube (baker/solve/gatherer.h) takes over its pixels, seen through the same elements and TexelLight.
//
// Why: a final-gather hemicube at R = 64 draws a few thousand triangles through llvmpipe (5.7 ms on the 100k level,
// one worker), where Embree traces 4,096 rays in 1.0 ms and scales with the cores; the gather sees only bounced light
// and sky, smooth enough that R² stratified rays give the hemicube's per-object error (per texel 2.3 % RMS against
// 1.9 % on the clean 10k level; twice the rays match it). docs/performance.md, "The final gather by rays".
//
// What a ray sees, as a hemicube pixel would:
//  - the front of an element: its radiance, plus scale × the TexelLight layer at the hit's lightmap UV (bilinear,
//    clamped at the layer's edge, as GL_LINEAR + GL_CLAMP_TO_EDGE samples it);
//  - a double-sided surface from either side: the copy whose front faces the ray (baker/rays/element_ray_scene.h);
//  - the back of a single-sided element: black, and counted (backfaceFraction, to find points inside geometry);
//  - nothing: the sky radiance.
// Ray origins are lifted off the surface by a fixed fraction of the scene diagonal (ElementRayScene::lift), so nothing
// nearer is missed whatever the ray's angle.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "baker/rays/element_ray_scene.h"
#include "baker/solve/gatherer.h"
#include "mesh/patches.h"
#include "raster/scene_buffers.h"

namespace hemibake {

class RayGatherer {
public:
    // Rays per point are rounded down to a square (strata × strata, at least 1): each stratum of the unit square
    // gets one jittered ray, mapped to the hemisphere by Malley's method. Typical: 4,096 (64 × 64, the medium
    // preset's R²). Builds an ElementRayScene over `mesh`; `mesh` must outlive this.
    // Throws std::runtime_error if Embree fails.
    RayGatherer(const PatchMesh& mesh, int raysPerPoint, std::uint64_t seed);
    // The same through an existing `scene` (e.g. SolvedScene::elementRays), which must outlive this.
    RayGatherer(const ElementRayScene& scene, int raysPerPoint, std::uint64_t seed);
    ~RayGatherer();
    RayGatherer(const RayGatherer&) = delete;
    RayGatherer& operator=(const RayGatherer&) = delete;

    // What the gathers see next: outgoing radiance per element (W·m⁻²·sr⁻¹), and light inside elements (nullptr:
    // none). Not thread-safe against a running gather.
    void setElementRadiance(std::vector<glm::vec3> radiance);
    void setTexelLight(std::shared_ptr<const TexelLight> light);
    // The share of back faces above which the caller calls a point inside geometry (the lightmap's
    // LightmapSettings::invalidBackfaceFraction, typically 0.1; default 1: no point is inside, and none is probed).
    // Points are probed only when it is at most kProbeMaxInsideBackFraction. Not thread-safe against a running gather.
    void setInsideBackFraction(double fraction) { insideBackFraction_ = fraction; }

    // What one gather traced.
    struct RayCounts {
        std::uint64_t traced = 0;         // rays traced
        std::uint64_t escaped = 0;        // of those, rays that met no surface (the sky's): what openings let out
        std::uint64_t stoppedInside = 0;  // points stopped after their probe (inside geometry)
    };

    // E/π at every point, in parallel over every core. A point's rays depend only on (`sweep`, its key): keys[k] for
    // point k (e.g. its texel index: a texel gets the same rays whatever else is gathered with it), or k when `keys`
    // is empty. `backfaceFraction`, if given, receives each point's share of rays that met the back of a single-sided
    // surface, and lets a point inside geometry stop early (when setInsideBackFraction allows): its probe (an 8 × 8
    // sub-lattice of its strata, 1/64 of its rays, traced first) meeting back faces on more than
    // kInsideProbeBackFraction of its rays stops it, and its E/π and share are the probe's (its light is not used:
    // the lightmap refills it from its neighbours). Every other point traces exactly the rays it would without the
    // probe, summed in the same order. Returns what was traced.
    // Throws std::invalid_argument if keys are given but not one per point.
    RayCounts gather(const std::vector<GatherPoint>& points, glm::vec3 skyRadiance, std::uint64_t sweep,
                     std::vector<glm::dvec3>& irradianceOverPi, std::vector<float>* backfaceFraction = nullptr,
                     std::span<const std::uint32_t> keys = {}) const;
    // The probe alone at every point, in parallel: the 8 × 8 sub-lattice of strata a gather traces first (the same
    // rays), its E/π and the standard error of that E/π's three channels summed, from the rays' spread (which overstates
    // it for stratified rays). A point inside geometry gets the probe's value like any other. Returns what was traced.
    // Throws std::logic_error unless canProbe(), std::invalid_argument as gather does.
    RayCounts probe(const std::vector<GatherPoint>& points, glm::vec3 skyRadiance, std::uint64_t sweep,
                    std::vector<glm::dvec3>& irradianceOverPi, std::vector<double>& standardError,
                    std::span<const std::uint32_t> keys = {}) const;
    // Whether points have a probe: at least 2·kProbeStrataPerSide strata a side (256 rays).
    bool canProbe() const { return strata_ >= 2 * kProbeStrataPerSide; }
    // A probe meeting back faces on more than this share of its rays stops its point. The lightmap calls a texel
    // inside geometry above a tenth (LightmapSettings::invalidBackfaceFraction); half a probe's 64 stratified rays is
    // far beyond any texel on the surface (a texel under an overlapping wall typically meets 90 % or more).
    static constexpr double kInsideProbeBackFraction = 0.5;
    // Probes only where the caller's inside share is at most this. A point on the surface whose true share is at that
    // bound meets back faces on more than half of 64 rays with a binomial chance of 2e-8 (6.2 σ; less, stratified);
    // at the lightmap's 0.1, 8e-17.
    static constexpr double kProbeMaxInsideBackFraction = 0.2;
    // Probes need at least this many strata a side (8 × 8 rays of a 16 × 16 point and more).
    static constexpr int kProbeStrataPerSide = 8;
    int raysPerPoint() const { return strata_ * strata_; }

private:
    // gather and probe: every ray of each point, or its probe only (standardError then filled).
    RayCounts trace(const std::vector<GatherPoint>& points, glm::vec3 skyRadiance, std::uint64_t sweep,
                    std::span<const std::uint32_t> keys, bool probeOnly, std::vector<glm::dvec3>& irradianceOverPi,
                    std::vector<float>* backfaceFraction, std::vector<double>* standardError) const;
    glm::dvec3 texelLightAt(std::uint32_t element, double b1, double b2) const;

    int strata_ = 1;
    std::uint64_t seed_ = 0;
    double insideBackFraction_ = 1.0;
    std::unique_ptr<ElementRayScene> ownScene_;  // when built here
    const ElementRayScene* scene_ = nullptr;
    std::vector<glm::vec3> radiance_;
    std::shared_ptr<const TexelLight> texelLight_;
};

}  // namespace hemibake
