#pragma once
// Light probes from a radiosity solution: a cube map of the solved scene's outgoing radiance around a point,
// projected into L2 SH of incident radiance with exact texel solid angles (CONVENTIONS.md "Spherical
// harmonics"), plus what the irradiance volume needs to avoid leaks: the back-face fraction (a probe inside
// geometry sees mostly back faces) and per-direction depth moments.
#include <cstddef>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "baker/probes/spherical_harmonics.h"
#include "baker/solve/radiosity_solution.h"
#include "mesh/patches.h"
#include "raster/cube_map_renderer.h"

namespace hemibake {

struct ProbeBakeSettings {
    int resolution = 32;              // cube face R×R texels
    ShWindow window = ShWindow::None;
    // A probe that sees more back faces than this fraction of the sphere is inside geometry (RTXGI uses 0.25).
    double insideBackfaceFraction = 0.25;
    int depthResolution = 16;         // D×D octahedral depth moments per probe (0 = none), as DDGI
    double maxDepthM = 0.0;           // distance recorded where nothing is hit (0 = the scene diagonal)
};

// What one cube map says about its probe.
struct CubeMapMeasurement {
    ShRgb sh;                         // incident radiance, unwindowed
    double backfaceFraction = 0.0;    // of 4π
    double skyFraction = 0.0;
    // The nearest back face (the shortest way out of a solid the probe is in), if any was seen.
    bool sawBackface = false;
    glm::dvec3 nearestBackfaceDirection{0.0};  // unit
    double nearestBackfaceDistanceM = 0.0;
    std::vector<glm::vec2> depthMoments;  // D×D (mean distance, mean squared distance), see volume_lookup.h
};

// Projection and statistics of a rendered cube map, without GL (tests feed it synthetic maps).
// `faceSolidAngles` from cubeFaceSolidAngles(image.resolution).
CubeMapMeasurement measureCubeMap(const CubeMapImage& image, std::span<const double> faceSolidAngles, int depthResolution,
                                  double maxDepthM);

struct ProbeRequest {
    glm::dvec3 position{0.0};
    // A probe inside geometry is moved out through its nearest back face, this far at most (0 = never moved:
    // it is only flagged), ending `relocationMarginM` beyond that face.
    double maxRelocationM = 0.0;
    double relocationMarginM = 0.0;
};

struct BakedProbe {
    glm::dvec3 requestedPosition{0.0};
    glm::dvec3 position{0.0};  // where it was rendered (differs when relocated)
    ShRgb sh;                  // incident radiance, window applied
    bool valid = true;
    bool relocated = false;
    double backfaceFraction = 0.0;
    double skyFraction = 0.0;
    std::vector<glm::vec2> depthMoments;
};

// Outgoing radiance per element for the probes' cube maps: displayRadiosity / π (= ρ·E/π + L_e), W·m⁻²·sr⁻¹.
std::vector<glm::vec3> elementOutgoingRadiance(const PatchMesh& mesh, const RadiositySolution& solution);

// Renders probes in parallel: one GL context + scene upload + cube-map renderer per worker thread.
class ProbeBaker {
public:
    // `mesh` must outlive the baker.
    ProbeBaker(const PatchMesh& mesh, std::span<const glm::vec3> elementRadiance, glm::vec3 skyRadiance,
               const ProbeBakeSettings& settings);
    ~ProbeBaker();
    ProbeBaker(const ProbeBaker&) = delete;
    ProbeBaker& operator=(const ProbeBaker&) = delete;

    // One probe per request, in order. `progress(done, total)` is called from worker threads, serialised.
    std::vector<BakedProbe> bake(std::span<const ProbeRequest> requests,
                                 const std::function<void(std::size_t, std::size_t)>& progress = {});
    // One probe on the calling thread.
    BakedProbe bakeOne(const ProbeRequest& request);

    const ProbeBakeSettings& settings() const { return settings_; }
    double maxDepthM() const { return maxDepthM_; }

private:
    struct Worker;
    struct Workers;
    Worker& local();

    const PatchMesh* mesh_;
    std::vector<glm::vec3> radiance_;
    glm::vec3 sky_;
    ProbeBakeSettings settings_;
    double maxDepthM_;
    std::vector<double> solidAngles_;
    std::unique_ptr<Workers> workers_;
};

}  // namespace hemibake
