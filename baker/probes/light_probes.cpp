#include "baker/probes/light_probes.h"

#include <algorithm>
#include <atomic>
#include <limits>
#include <cmath>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "baker/probes/cube_map_solid_angle.h"
#include "baker/probes/volume_lookup.h"
#include "mesh/frame_math.h"
#include "raster/gl_context.h"
#include "raster/scene_buffers.h"

namespace hemibake {

namespace {

// Texel of a cube map in direction d (for octahedral texels that no cube texel fell into).
const glm::vec4& cubeTexelAt(const CubeMapImage& image, const glm::dvec3& d) {
    const int face = cubeFaceOf(d);
    const CubeFaceBasis& b = cubeFaceBasis(face);
    const double forward = glm::dot(d, b.forward);
    const double s = glm::dot(d, b.right) / forward, t = glm::dot(d, b.up) / forward;
    const int r = image.resolution;
    const int i = std::clamp(int(std::floor((s + 1.0) * 0.5 * r)), 0, r - 1);
    const int j = std::clamp(int(std::floor((t + 1.0) * 0.5 * r)), 0, r - 1);
    return image.at(face, i, j);
}

}  // namespace

CubeMapMeasurement measureCubeMap(const CubeMapImage& image, std::span<const double> faceSolidAngles, int depthResolution,
                                  double maxDepthM) {
    const int r = image.resolution;
    if (faceSolidAngles.size() != std::size_t(r) * std::size_t(r))
        throw std::invalid_argument("measureCubeMap: solid angles for a different resolution");
    CubeMapMeasurement m;
    const std::size_t depthTexels = std::size_t(depthResolution) * std::size_t(depthResolution);
    std::vector<glm::dvec3> moments(depthTexels, glm::dvec3(0.0));  // Σω, Σω·d, Σω·d²
    double backface = 0.0, sky = 0.0;
    m.nearestBackfaceDistanceM = std::numeric_limits<double>::infinity();
    for (int face = 0; face < CubeMapImage::kFaceCount; ++face)
        for (int j = 0; j < r; ++j)
            for (int i = 0; i < r; ++i) {
                const glm::vec4& texel = image.at(face, i, j);
                const glm::dvec3 d = glm::normalize(image.direction(face, i, j));
                const double omega = faceSolidAngles[std::size_t(j) * std::size_t(r) + std::size_t(i)];
                m.sh.addSample(d, glm::dvec3(texel.x, texel.y, texel.z), omega);
                double distance = maxDepthM;
                if (texel.w == 0.0f) {
                    sky += omega;
                } else if (texel.w < 0.0f) {
                    backface += omega;
                    distance = std::min(maxDepthM, double(-texel.w));
                    if (-texel.w < m.nearestBackfaceDistanceM) {
                        m.nearestBackfaceDistanceM = -texel.w;
                        m.nearestBackfaceDirection = d;
                        m.sawBackface = true;
                    }
                } else {
                    distance = std::min(maxDepthM, double(texel.w));
                }
                if (depthResolution > 0) {
                    const glm::dvec2 uv = octahedralEncode(d) * double(depthResolution);
                    const int u = std::clamp(int(uv.x), 0, depthResolution - 1);
                    const int v = std::clamp(int(uv.y), 0, depthResolution - 1);
                    moments[std::size_t(v) * std::size_t(depthResolution) + std::size_t(u)] +=
                        omega * glm::dvec3(1.0, distance, distance * distance);
                }
            }
    if (!m.sawBackface) m.nearestBackfaceDistanceM = 0.0;
    m.backfaceFraction = backface / (4.0 * std::numbers::pi);
    m.skyFraction = sky / (4.0 * std::numbers::pi);
    m.depthMoments.resize(depthTexels);
    for (int v = 0; v < depthResolution; ++v)
        for (int u = 0; u < depthResolution; ++u) {
            const std::size_t k = std::size_t(v) * std::size_t(depthResolution) + std::size_t(u);
            if (moments[k].x > 0.0) {
                m.depthMoments[k] = glm::vec2(moments[k].y / moments[k].x, moments[k].z / moments[k].x);
            } else {  // finer depth map than cube map: take the texel the octahedral texel's centre falls in
                const glm::vec4& t = cubeTexelAt(image, octahedralDecode((glm::dvec2(u, v) + 0.5) / double(depthResolution)));
                const double d = t.w == 0.0f ? maxDepthM : std::min(maxDepthM, double(std::abs(t.w)));
                m.depthMoments[k] = glm::vec2(float(d), float(d * d));
            }
        }
    return m;
}

std::vector<glm::vec3> elementOutgoingRadiance(const PatchMesh& mesh, const RadiositySolution& solution) {
    std::vector<glm::vec3> out(mesh.elements.size());
    for (std::size_t e = 0; e < out.size(); ++e) out[e] = glm::vec3(solution.displayRadiosity(mesh, e) / std::numbers::pi);
    return out;
}

struct ProbeBaker::Worker {
    GlContext context;
    SceneBuffers buffers;
    CubeMapRenderer renderer;
    CubeMapImage image;
    Worker(const PatchMesh& mesh, std::span<const glm::vec3> radiance, int resolution)
        : context(), buffers(context, mesh), renderer(buffers, resolution) {
        buffers.setElementRadiance(radiance);
    }
};

struct ProbeBaker::Workers {
    tbb::enumerable_thread_specific<std::unique_ptr<Worker>> perThread;
};

ProbeBaker::ProbeBaker(const PatchMesh& mesh, std::span<const glm::vec3> elementRadiance, glm::vec3 skyRadiance,
                       const ProbeBakeSettings& settings)
    : mesh_(&mesh), radiance_(elementRadiance.begin(), elementRadiance.end()), sky_(skyRadiance), settings_(settings),
      maxDepthM_(settings.maxDepthM > 0.0 ? settings.maxDepthM : mesh.sceneDiagonalM),
      workers_(std::make_unique<Workers>()) {
    if (radiance_.size() != mesh.elements.size())
        throw std::invalid_argument("ProbeBaker: " + std::to_string(radiance_.size()) + " radiance values for " +
                                    std::to_string(mesh.elements.size()) + " elements");
    if (settings.resolution < 2 || settings.resolution > 1024)
        throw std::invalid_argument("probe resolution must be in [2, 1024], got " + std::to_string(settings.resolution));
    if (settings.depthResolution < 0 || settings.depthResolution > 64)
        throw std::invalid_argument("probe depth map resolution must be in [0, 64]");
    solidAngles_ = cubeFaceSolidAngles(settings.resolution);
}

ProbeBaker::~ProbeBaker() = default;

ProbeBaker::Worker& ProbeBaker::local() {
    std::unique_ptr<Worker>& worker = workers_->perThread.local();
    if (!worker) worker = std::make_unique<Worker>(*mesh_, radiance_, settings_.resolution);
    return *worker;
}

BakedProbe ProbeBaker::bakeOne(const ProbeRequest& request) {
    Worker& worker = local();
    auto measure = [&](const glm::dvec3& position) {
        worker.renderer.render(position, sky_, worker.image);
        return measureCubeMap(worker.image, solidAngles_, settings_.depthResolution, maxDepthM_);
    };
    BakedProbe probe;
    probe.requestedPosition = probe.position = request.position;
    CubeMapMeasurement m = measure(request.position);
    if (m.backfaceFraction > settings_.insideBackfaceFraction) {
        probe.valid = false;
        // Inside a closed solid, the nearest back face is the nearest way out: step just beyond it and check.
        const double step = m.nearestBackfaceDistanceM + request.relocationMarginM;
        if (m.sawBackface && request.maxRelocationM > 0.0 && step <= request.maxRelocationM) {
            const glm::dvec3 moved = request.position + step * m.nearestBackfaceDirection;
            CubeMapMeasurement there = measure(moved);
            if (there.backfaceFraction <= settings_.insideBackfaceFraction) {
                m = std::move(there);
                probe.position = moved;
                probe.valid = probe.relocated = true;
            }
        }
    }
    probe.sh = m.sh;
    probe.sh.scaleBands(shWindowWeights(settings_.window));
    probe.backfaceFraction = m.backfaceFraction;
    probe.skyFraction = m.skyFraction;
    probe.depthMoments = std::move(m.depthMoments);
    return probe;
}

std::vector<BakedProbe> ProbeBaker::bake(std::span<const ProbeRequest> requests,
                                         const std::function<void(std::size_t, std::size_t)>& progress) {
    std::vector<BakedProbe> probes(requests.size());
    std::atomic<std::size_t> done{0};
    std::mutex progressMutex;
    tbb::parallel_for(std::size_t(0), requests.size(), [&](std::size_t k) {
        probes[k] = bakeOne(requests[k]);
        const std::size_t n = ++done;
        if (progress && (n % 64 == 0 || n == requests.size())) {
            std::lock_guard lock(progressMutex);
            progress(n, requests.size());
        }
    });
    return probes;
}

}  // namespace hemibake
