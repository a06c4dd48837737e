#include "raster/hemicube_pool.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace hemibake {

HemicubePool::Worker::Worker(const PatchMesh& mesh, int resolution, const OcclusionCullingSettings& occlusion)
    : context(), buffers(context, mesh), renderer(buffers, resolution, occlusion) {}

HemicubePool::HemicubePool(const PatchMesh& mesh, int resolution, const OcclusionCullingSettings& occlusion)
    : mesh_(&mesh), resolution_(resolution), occlusion_(occlusion) {
    // Reject a bad resolution here rather than on the first worker thread.
    if (resolution < 2 || resolution % 2 != 0)
        throw std::invalid_argument("HemicubePool: resolution must be even and >= 2, got " + std::to_string(resolution));
}

HemicubePool::~HemicubePool() = default;

HemicubeRenderer& HemicubePool::local() {
    std::unique_ptr<Worker>& worker = workers_.local();
    if (!worker) worker = std::make_unique<Worker>(*mesh_, resolution_, occlusion_);
    if (worker->radianceVersion != radianceVersion_) {
        worker->buffers.setElementRadiance(radiance_);
        worker->radianceVersion = radianceVersion_;
    }
    if (worker->texelLightVersion != texelLightVersion_) {
        if (texelLight_)
            worker->buffers.setTexelLight(*texelLight_);
        else
            worker->buffers.clearTexelLight();
        worker->texelLightVersion = texelLightVersion_;
    }
    return worker->renderer;
}

HemicubeDrawTotals HemicubePool::drawTotals() const {
    HemicubeDrawTotals total;
    for (const std::unique_ptr<Worker>& worker : workers_)
        if (worker) total += worker->renderer.drawTotals();
    return total;
}

void HemicubePool::setTexelLight(std::shared_ptr<const TexelLight> light) {
    texelLight_ = std::move(light);
    ++texelLightVersion_;
}

void HemicubePool::setElementRadiance(std::span<const glm::vec3> radiance) {
    if (radiance.size() != mesh_->elements.size())
        throw GlError("HemicubePool::setElementRadiance: got " + std::to_string(radiance.size()) + " values for " +
                      std::to_string(mesh_->elements.size()) + " elements");
    radiance_.assign(radiance.begin(), radiance.end());
    ++radianceVersion_;
}

}  // namespace hemibake
