#pragma once
// One GL context + scene upload + hemicube renderer per worker thread, created on the thread's first use,
// so callers can run tbb::parallel_for over hemicube work:
//
//   HemicubePool pool(mesh, 128);
//   tbb::parallel_for(0, n, [&](int i) { pool.local().renderFormFactors(frame(i), lists.local()); });
//
// llvmpipe runs each context's vertex stage on one thread, so contexts are never shared between workers.
// (llvmpipe's own rasterizer threads, LP_NUM_THREADS, made no measurable difference on top of this:
// docs/performance.md.)
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "raster/hemicube.h"

namespace hemibake {

class HemicubePool {
public:
    // `mesh` must outlive the pool: each worker uploads it when it first asks for its renderer. Every renderer
    // culls with `occlusion` (which changes the cost, never the result).
    HemicubePool(const PatchMesh& mesh, int resolution, const OcclusionCullingSettings& occlusion = {});
    ~HemicubePool();
    HemicubePool(const HemicubePool&) = delete;
    HemicubePool& operator=(const HemicubePool&) = delete;

    // The calling thread's renderer, with the latest element radiance uploaded.
    HemicubeRenderer& local();

    // Radiance per element for the next gather sweep (W·m⁻²·sr⁻¹). Workers upload it lazily, on their next
    // local(); must not be called while other threads are inside local() or rendering.
    void setElementRadiance(std::span<const glm::vec3> radiance);

    // Light varying inside elements for the next gathers (SceneBuffers::setTexelLight), uploaded lazily like the
    // radiance; same threading rule. `light` is kept by the pool; nullptr turns it off.
    void setTexelLight(std::shared_ptr<const TexelLight> light);

    // What every worker's renderer drew so far. Must not be called while others render.
    HemicubeDrawTotals drawTotals() const;

    std::size_t workerCount() const { return workers_.size(); }
    int resolution() const { return resolution_; }

private:
    struct Worker {
        GlContext context;
        SceneBuffers buffers;
        HemicubeRenderer renderer;
        std::uint64_t radianceVersion = 0;
        std::uint64_t texelLightVersion = 0;
        Worker(const PatchMesh& mesh, int resolution, const OcclusionCullingSettings& occlusion);
    };

    const PatchMesh* mesh_;
    int resolution_;
    OcclusionCullingSettings occlusion_;
    std::vector<glm::vec3> radiance_;
    std::uint64_t radianceVersion_ = 0;  // 0 = never set: buffers start at zero radiance
    std::shared_ptr<const TexelLight> texelLight_;
    std::uint64_t texelLightVersion_ = 0;  // 0 = never set
    tbb::enumerable_thread_specific<std::unique_ptr<Worker>> workers_;  // last: dies first
};

}  // namespace hemibake
